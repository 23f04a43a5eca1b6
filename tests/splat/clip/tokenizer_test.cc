#include "splat/clip/tokenizer.h"

#include <gtest/gtest.h>

#include <fstream>

#include "splat/error.h"
#include "tests/test_util.h"
#include "tests/tiny_clip.h"

namespace splat {
namespace {

namespace fs = std::filesystem;

const ClipTokenizer& tokenizer() {
  static const ClipTokenizer t(testing_util::tiny_clip_dir() / "vocab.json",
                               testing_util::tiny_clip_dir() / "merges.txt");
  return t;
}

TEST(ClipTokenizer, TruncatesAt77TokensEndingWithEndOfText) {
  const ClipTokenizer tokenizer(testing_util::tiny_clip_dir() / "vocab.json",
                                testing_util::tiny_clip_dir() / "merges.txt");
  std::string text;
  for (int i = 0; i < 100; ++i) text += "chair ";
  const std::vector<int32_t> ids = tokenizer.encode(text);
  ASSERT_EQ(ids.size(), 77u);
  EXPECT_EQ(ids.front(), tokenizer.start_token());
  EXPECT_EQ(ids.back(), tokenizer.end_token());
  EXPECT_EQ(tokenizer.encode("").size(), 2u);
}

TEST(ClipTokenizer, CleansLikeThePythonReference) {
  EXPECT_EQ(ClipTokenizer::clean("  The\t RED\u00a0Chair \n"), "the red chair");
  EXPECT_EQ(ClipTokenizer::clean("fish &amp;amp; chips &#x263A; &ampx"), "fish & chips \u263a &x");
  EXPECT_EQ(ClipTokenizer::clean("\u0130"), "i\u0307");  // full lower-casing
  EXPECT_EQ(ClipTokenizer::clean("e\u0301"), "\u00e9");  // NFC
  const std::vector<std::string> words = ClipTokenizer::split_words("don't stop!! 42x");
  EXPECT_EQ(words, (std::vector<std::string>{"don", "'t", "stop", "!!", "4", "2", "x"}));
}

TEST(ClipTokenizer, MissingOrMalformedFilesNameTheFile) {
  const testing_util::TempDir tmp;
  const fs::path dir = tmp.path();
  std::ofstream(dir / "vocab.json") << "{\"a\": 1";
  try {
    ClipTokenizer(dir / "vocab.json", testing_util::tiny_clip_dir() / "merges.txt");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vocab.json"), std::string::npos);
  }
  EXPECT_THROW(ClipTokenizer(testing_util::tiny_clip_dir() / "vocab.json", dir / "none.txt"),
               InputError);
  // A token ID beyond int32 is refused, not converted (undefined behaviour).
  std::ofstream(dir / "big.json") << "{\"a\": 1e20}";
  try {
    ClipTokenizer(dir / "big.json", testing_util::tiny_clip_dir() / "merges.txt");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"a\" is 1e+20, not an integer"), std::string::npos)
        << e.what();
  }
}

TEST(ClipTokenizer, SplitsContractionsLettersDigitsAndSymbols) {
  EXPECT_EQ(ClipTokenizer::split_words("we'll they're i've i'm he'd it's"),
            (std::vector<std::string>{"we", "'ll", "they", "'re", "i", "'ve", "i", "'m", "he", "'d",
                                      "it", "'s"}));
  EXPECT_EQ(ClipTokenizer::split_words("r2d2 3.5kg"),
            (std::vector<std::string>{"r", "2", "d", "2", "3", ".", "5", "kg"}));
  // Special tokens stay whole; letters of any script form words.
  EXPECT_EQ(ClipTokenizer::split_words("<|startoftext|>caf\u00e9 \u732b<|endoftext|>"),
            (std::vector<std::string>{"<|startoftext|>", "caf\u00e9", "\u732b", "<|endoftext|>"}));
  EXPECT_TRUE(ClipTokenizer::split_words("   ").empty());
}

TEST(ClipTokenizer, PromptsThatCleanAlikeEncodeAlike) {
  const ClipTokenizer& t = tokenizer();
  const std::vector<int32_t> base = t.encode("a red toy chair");
  EXPECT_EQ(t.encode("  A   RED\ttoy CHAIR\n"), base);  // case and whitespace
  EXPECT_EQ(t.encode("a red toy &#99;hair"), base);     // numeric references
  EXPECT_NE(t.encode("a red toy chairs"), base);
}

TEST(ClipTokenizer, WordsEncodeIndependentlyOfTheirNeighbours) {
  // BPE works inside one word ("</w>" ends it), so a prompt's tokens are its
  // words' tokens in order, between the start and end tokens.
  const ClipTokenizer& t = tokenizer();
  const auto inner = [&](const std::string& text) {
    std::vector<int32_t> ids = t.encode(text);
    return std::vector<int32_t>(ids.begin() + 1, ids.end() - 1);
  };
  std::vector<int32_t> joined = inner("porcelain");
  const std::vector<int32_t> hand = inner("hand");
  joined.insert(joined.end(), hand.begin(), hand.end());
  EXPECT_EQ(inner("porcelain hand"), joined);
  EXPECT_EQ(t.encode("porcelain hand").front(), t.start_token());
  EXPECT_EQ(t.encode("porcelain hand").back(), t.end_token());
}

TEST(ClipTokenizer, ShortContextKeepsStartAndEnd) {
  const std::vector<int32_t> ids = tokenizer().encode("a green apple on a plate", 4);
  ASSERT_EQ(ids.size(), 4u);
  EXPECT_EQ(ids.front(), tokenizer().start_token());
  EXPECT_EQ(ids.back(), tokenizer().end_token());
  for (int32_t id : tokenizer().encode("any words at all \u2603"))
    EXPECT_LT(size_t(id), tokenizer().vocabulary_size());
}

}  // namespace
}  // namespace splat
