#pragma once
// CLIP's byte-level BPE tokenizer (OpenAI's simple_tokenizer.py, as the
// openai/clip-vit-base-patch16 release ships it in vocab.json and merges.txt).
//
// Prompt handling, in order:
//   1. Unicode NFC normalisation (OpenAI applies ftfy.fix_text, whose mojibake
//      repair has no C++ counterpart; on text typed by a person it amounts to
//      NFC);
//   2. HTML character references unescaped twice, as html.unescape does: every
//      numeric reference, and the named ones amp, lt, gt, quot, apos, nbsp;
//   3. whitespace runs (Python's str.isspace) collapsed to one space, ends
//      stripped, then full Unicode lower-casing;
//   4. split with CLIP's pattern (contractions, letter runs, single digits,
//      runs of other symbols; the special tokens kept whole), each piece
//      byte-encoded and merged by BPE rank, with "</w>" ending each word;
//   5. <|startoftext|> ... <|endoftext|>, truncated to the context length (77)
//      with the last token replaced by <|endoftext|>, as clip.tokenize does.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace splat {

class ClipTokenizer {
 public:
  // Throws InputError naming the file when either is missing or malformed.
  ClipTokenizer(const std::filesystem::path& vocab_json, const std::filesystem::path& merges_txt);

  // Token IDs with the start and end tokens, at most context_length of them.
  std::vector<int32_t> encode(std::string_view text, size_t context_length = 77) const;

  // Steps 1-3 (UTF-8 in and out).
  static std::string clean(std::string_view text);
  // Step 4's split, before byte encoding (UTF-8 pieces).
  static std::vector<std::string> split_words(const std::string& cleaned);

  int32_t start_token() const { return start_; }
  int32_t end_token() const { return end_; }
  size_t vocabulary_size() const { return vocab_.size(); }

 private:
  std::vector<std::string> bpe(const std::string& word) const;

  std::filesystem::path vocab_file_;
  std::unordered_map<std::string, int32_t> vocab_;
  std::unordered_map<std::string, int32_t> merge_ranks_;  // "a b" -> rank
  std::vector<std::string> byte_symbols_;                 // byte -> UTF-8 symbol
  int32_t start_ = -1, end_ = -1;
};

}  // namespace splat
