#pragma once
// BvhTokenizer: splits the HIERARCHY part of a BVH file into whitespace-separated
// tokens, remembering the 1-based line and column of each. It runs over a
// string_view of the whole file and never copies it.
//
// Line ends: LF, CRLF and a lone CR (old Mac exports) each end one line. Space,
// tab, form feed and vertical tab separate tokens. '{' and '}' are always tokens
// of their own, even when glued to a name ("Hips{"). Columns count bytes from the
// start of the line (a tab counts as one column, as GCC does).
//
// The tokenizer knows nothing of the grammar: keywords are plain tokens; the
// document parser compares them without regard to case.

#include <cstddef>
#include <string_view>

namespace mocap {

struct BvhToken {
  std::string_view text;   // empty at end of input
  int line = 0;            // 1-based line of the first character
  int column = 0;          // 1-based column of the first character
  std::size_t offset = 0;  // byte offset of the first character in the input

  bool empty() const { return text.empty(); }
};

class BvhTokenizer {
 public:
  explicit BvhTokenizer(std::string_view input) : input_(input) {}

  // The next token, or an empty token (text empty, location at the end) when
  // the input is exhausted.
  BvhToken Next();
  // The next token without consuming it.
  BvhToken Peek();

  // The rest of the current line after the last token returned, up to (not
  // including) a '{' or the line end, with surrounding blanks removed; consumes
  // it. Used for names, which may contain spaces ("JOINT Left Arm"). Returns
  // an empty view when only blanks follow. `loc` receives the location of the
  // first character of the name.
  std::string_view RestOfLineName(BvhToken* loc);

  // Position just after the last token consumed, for handing over to the
  // motion parser.
  std::size_t offset() const { return pos_; }
  int line() const { return line_; }
  int column() const { return static_cast<int>(pos_ - line_start_) + 1; }

  // The location of the end of the input (for "unexpected end of file").
  BvhToken EndLocation();

 private:
  void SkipBlanks();  // skips spaces and line ends, counting lines

  std::string_view input_;
  std::size_t pos_ = 0;
  int line_ = 1;
  std::size_t line_start_ = 0;  // offset of the first byte of the current line
};

// True for the bytes that separate tokens within a line.
inline bool IsBvhBlank(char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; }

// Case-insensitive ASCII comparison of a token with a keyword.
bool BvhKeywordEquals(std::string_view token, std::string_view keyword);

}  // namespace mocap
