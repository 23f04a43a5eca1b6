#include "splat/clip/tokenizer.h"

#include <fmt/format.h>
#include <unicode/locid.h>
#include <unicode/normalizer2.h>
#include <unicode/uchar.h>
#include <unicode/unistr.h>

#include <array>
#include <climits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/json_integer.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

std::u32string to_u32(const icu::UnicodeString& s) {
  std::u32string out;
  for (int32_t i = 0; i < s.length(); i = s.moveIndex32(i, 1))
    out.push_back(char32_t(s.char32At(i)));
  return out;
}

icu::UnicodeString from_u32(const std::u32string& s) {
  icu::UnicodeString out;
  for (char32_t c : s) out.append(UChar32(c));
  return out;
}

std::string to_utf8(const icu::UnicodeString& s) {
  std::string out;
  s.toUTF8String(out);
  return out;
}

// Python's str.isspace: general category Zs, or bidirectional class WS, B or S.
bool is_python_space(char32_t c) {
  const UCharDirection d = u_charDirection(UChar32(c));
  return u_charType(UChar32(c)) == U_SPACE_SEPARATOR || d == U_WHITE_SPACE_NEUTRAL ||
         d == U_BLOCK_SEPARATOR || d == U_SEGMENT_SEPARATOR;
}

bool is_letter(char32_t c) { return (U_GET_GC_MASK(UChar32(c)) & U_GC_L_MASK) != 0; }
bool is_number(char32_t c) { return (U_GET_GC_MASK(UChar32(c)) & U_GC_N_MASK) != 0; }
bool is_regex_space(char32_t c) { return u_isUWhiteSpace(UChar32(c)); }

// html.unescape's rules for a numeric character reference.
std::u32string numeric_reference(uint64_t n) {
  // Windows-1252 code points that HTML5 maps 0x80..0x9f to.
  static constexpr std::array<char32_t, 32> kCp1252 = {
      0x20ac, 0x81,   0x201a, 0x0192, 0x201e, 0x2026, 0x2020, 0x2021, 0x02c6, 0x2030, 0x0160,
      0x2039, 0x0152, 0x8d,   0x017d, 0x8f,   0x90,   0x2018, 0x2019, 0x201c, 0x201d, 0x2022,
      0x2013, 0x2014, 0x02dc, 0x2122, 0x0161, 0x203a, 0x0153, 0x9d,   0x017e, 0x0178};
  if (n == 0) return U"\uFFFD";
  if (n == 0x0d) return U"\r";
  if (n >= 0x80 && n <= 0x9f) return std::u32string(1, kCp1252[n - 0x80]);
  if ((n >= 0xd800 && n <= 0xdfff) || n > 0x10ffff) return U"\uFFFD";
  const bool invalid = (n >= 0x1 && n <= 0x8) || n == 0xb || (n >= 0xe && n <= 0x1f) ||
                       (n >= 0x7f && n <= 0x9f) || (n >= 0xfdd0 && n <= 0xfdef) ||
                       (n & 0xfffe) == 0xfffe;
  return invalid ? U"" : std::u32string(1, char32_t(n));
}

// The named references this tokenizer knows; those without ';' are HTML's
// legacy forms, which html.unescape also accepts as a prefix ("&ampx" -> "&x").
const std::vector<std::pair<std::u32string, char32_t>>& named_references() {
  static const std::vector<std::pair<std::u32string, char32_t>> kNames = {
      {U"amp;", U'&'},   {U"amp", U'&'},   {U"lt;", U'<'},   {U"lt", U'<'},
      {U"gt;", U'>'},    {U"gt", U'>'},    {U"quot;", U'"'}, {U"quot", U'"'},
      {U"apos;", U'\''}, {U"nbsp;", 0xa0}, {U"nbsp", 0xa0}};
  return kNames;
}

bool is_hex(char32_t c) { return std::isxdigit(c < 128 ? int(c) : 0) != 0; }

// One pass of html.unescape.
std::u32string unescape_html(const std::u32string& s) {
  std::u32string out;
  size_t i = 0;
  while (i < s.size()) {
    if (s[i] != U'&' || i + 1 >= s.size()) {
      out.push_back(s[i++]);
      continue;
    }
    size_t j = i + 1;
    if (s[j] == U'#') {
      const bool hex = j + 1 < s.size() && (s[j + 1] == U'x' || s[j + 1] == U'X');
      size_t k = j + (hex ? 2 : 1), start = k;
      uint64_t n = 0;
      while (k < s.size() && (hex ? is_hex(s[k]) : (s[k] >= U'0' && s[k] <= U'9'))) {
        const char32_t c = s[k++];
        const uint64_t digit = c <= U'9' ? c - U'0' : (c | 0x20) - U'a' + 10;
        n = std::min<uint64_t>(n * (hex ? 16 : 10) + digit, uint64_t(1) << 40);
      }
      if (k == start) {  // "&#" with no digits: kept as it is
        out.push_back(s[i++]);
        continue;
      }
      if (k < s.size() && s[k] == U';') ++k;
      out += numeric_reference(n);
      i = k;
      continue;
    }
    // A name: up to 32 characters other than \t \n \f space < & # ;, then ';'?
    size_t k = j;
    while (k < s.size() && k - j < 32 &&
           std::u32string_view(U"\t\n\f <&#;").find(s[k]) == std::u32string_view::npos)
      ++k;
    if (k == j) {
      out.push_back(s[i++]);
      continue;
    }
    if (k < s.size() && s[k] == U';') ++k;
    const std::u32string name = s.substr(j, k - j);
    bool replaced = false;
    for (const auto& [ref, c] : named_references())
      if (name == ref) out.push_back(c), replaced = true;
    for (size_t x = name.size() - 1; !replaced && x > 1; --x)
      for (const auto& [ref, c] : named_references())
        if (!replaced && ref.back() != U';' && name.compare(0, x, ref) == 0 && ref.size() == x)
          out.push_back(c), out += name.substr(x), replaced = true;
    if (!replaced) out += U"&" + name;
    i = k;
  }
  return out;
}

std::u32string collapse_whitespace(const std::u32string& s) {
  std::u32string out;
  bool space = false;
  for (char32_t c : s) {
    if (is_python_space(c)) {
      space = true;
      continue;
    }
    if (space && !out.empty()) out.push_back(U' ');
    space = false;
    out.push_back(c);
  }
  return out;
}

// OpenAI's bytes_to_unicode: printable bytes stand for themselves, the rest
// for the code points from 256 on.
std::vector<std::string> byte_symbols() {
  std::vector<std::string> symbols(256);
  int next = 256;
  for (int b = 0; b < 256; ++b) {
    const bool printable = (b >= '!' && b <= '~') || (b >= 0xa1 && b <= 0xac) || (b >= 0xae);
    symbols[b] = to_utf8(icu::UnicodeString(UChar32(printable ? b : next++)));
  }
  return symbols;
}

const std::u32string kStartText = U"<|startoftext|>", kEndText = U"<|endoftext|>";

}  // namespace

ClipTokenizer::ClipTokenizer(const fs::path& vocab_json, const fs::path& merges_txt)
    : vocab_file_(vocab_json), byte_symbols_(byte_symbols()) {
  try {
    const auto vocab = nlohmann::json::parse(read_text_file(vocab_json));
    for (const auto& [token, id] : vocab.items())
      vocab_.emplace(token, json_integer<int32_t>(id, vocab_json, token.c_str()));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(vocab_json, std::string("not a CLIP vocabulary: ") + e.what());
  }
  const auto find = [&](const std::string& token) {
    const auto it = vocab_.find(token);
    if (it == vocab_.end()) throw InputError(vocab_json, "has no " + token + " token");
    return it->second;
  };
  start_ = find("<|startoftext|>");
  end_ = find("<|endoftext|>");
  for (const std::string& s : byte_symbols_) find(s), find(s + "</w>");

  std::istringstream merges(read_text_file(merges_txt));
  std::string line;
  int32_t rank = 0, line_number = 0;
  while (std::getline(merges, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line.rfind("#version", 0) == 0) continue;
    const size_t space = line.find(' ');
    if (space == std::string::npos || space == 0 || space + 1 == line.size() ||
        line.find(' ', space + 1) != std::string::npos)
      throw InputError(merges_txt, fmt::format("line {}: not a merge \"a b\"", line_number));
    merge_ranks_.emplace(line, rank++);
  }
  if (merge_ranks_.empty()) throw InputError(merges_txt, "has no merges");
}

std::string ClipTokenizer::clean(std::string_view text) {
  UErrorCode status = U_ZERO_ERROR;
  const icu::Normalizer2* nfc = icu::Normalizer2::getNFCInstance(status);
  icu::UnicodeString u =
      icu::UnicodeString::fromUTF8(icu::StringPiece(text.data(), int32_t(text.size())));
  if (U_SUCCESS(status)) u = nfc->normalize(u, status);
  if (U_FAILURE(status)) throw std::runtime_error("ICU normalisation failed");
  std::u32string s = collapse_whitespace(unescape_html(unescape_html(to_u32(u))));
  icu::UnicodeString lower = from_u32(s);
  lower.toLower(icu::Locale::getRoot());
  return to_utf8(lower);
}

std::vector<std::string> ClipTokenizer::split_words(const std::string& cleaned) {
  const std::u32string s = to_u32(icu::UnicodeString::fromUTF8(cleaned));
  std::vector<std::string> words;
  const auto emit = [&](size_t begin, size_t end) {
    words.push_back(to_utf8(from_u32(s.substr(begin, end - begin))));
  };
  size_t i = 0;
  while (i < s.size()) {
    const char32_t c = s[i];
    size_t end = i;
    if (s.compare(i, kStartText.size(), kStartText) == 0) {
      end = i + kStartText.size();
    } else if (s.compare(i, kEndText.size(), kEndText) == 0) {
      end = i + kEndText.size();
    } else if (c == U'\'' && i + 1 < s.size() &&
               std::u32string_view(U"stmd").find(s[i + 1]) != std::u32string_view::npos) {
      end = i + 2;
    } else if (c == U'\'' && (s.compare(i, 3, U"'re") == 0 || s.compare(i, 3, U"'ve") == 0 ||
                              s.compare(i, 3, U"'ll") == 0)) {
      end = i + 3;
    } else if (is_letter(c)) {
      for (end = i; end < s.size() && is_letter(s[end]);) ++end;
    } else if (is_number(c)) {
      end = i + 1;
    } else if (!is_regex_space(c)) {
      for (end = i;
           end < s.size() && !is_regex_space(s[end]) && !is_letter(s[end]) && !is_number(s[end]);)
        ++end;
    } else {
      ++i;  // whitespace between pieces
      continue;
    }
    emit(i, end);
    i = end;
  }
  return words;
}

std::vector<std::string> ClipTokenizer::bpe(const std::string& word) const {
  std::vector<std::string> symbols;
  for (unsigned char b : word) symbols.push_back(byte_symbols_[b]);
  symbols.back() += "</w>";
  while (symbols.size() > 1) {
    int32_t best = INT32_MAX;
    std::string best_key;
    for (size_t i = 0; i + 1 < symbols.size(); ++i) {
      const auto it = merge_ranks_.find(symbols[i] + " " + symbols[i + 1]);
      if (it != merge_ranks_.end() && it->second < best) best = it->second, best_key = it->first;
    }
    if (best == INT32_MAX) break;
    const std::string first = best_key.substr(0, best_key.find(' '));
    const std::string second = best_key.substr(best_key.find(' ') + 1);
    std::vector<std::string> merged;
    for (size_t i = 0; i < symbols.size(); ++i) {
      if (i + 1 < symbols.size() && symbols[i] == first && symbols[i + 1] == second) {
        merged.push_back(first + second);
        ++i;
      } else {
        merged.push_back(symbols[i]);
      }
    }
    symbols = std::move(merged);
  }
  return symbols;
}

std::vector<int32_t> ClipTokenizer::encode(std::string_view text, size_t context_length) const {
  std::vector<int32_t> ids = {start_};
  for (const std::string& word : split_words(clean(text))) {
    if (word == "<|startoftext|>" || word == "<|endoftext|>") {
      ids.push_back(word == "<|startoftext|>" ? start_ : end_);
      continue;
    }
    for (const std::string& symbol : bpe(word)) {
      const auto it = vocab_.find(symbol);
      if (it == vocab_.end())
        throw InputError(vocab_file_, fmt::format("token \"{}\" is not in the vocabulary", symbol));
      ids.push_back(it->second);
    }
  }
  ids.push_back(end_);
  if (context_length >= 2 && ids.size() > context_length) {
    ids.resize(context_length);
    ids.back() = end_;
  }
  return ids;
}

}  // namespace splat
