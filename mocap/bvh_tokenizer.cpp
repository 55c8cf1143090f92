#include "mocap/bvh_tokenizer.h"

namespace mocap {

namespace {

bool IsTokenEnd(char c) { return IsBvhBlank(c) || c == '\n' || c == '\r' || c == '{' || c == '}'; }

char ToLowerAscii(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

}  // namespace

bool BvhKeywordEquals(std::string_view token, std::string_view keyword) {
  if (token.size() != keyword.size()) return false;
  for (std::size_t i = 0; i < token.size(); ++i) {
    if (ToLowerAscii(token[i]) != ToLowerAscii(keyword[i])) return false;
  }
  return true;
}

void BvhTokenizer::SkipBlanks() {
  const std::size_t n = input_.size();
  while (pos_ < n) {
    const char c = input_[pos_];
    if (IsBvhBlank(c)) {
      ++pos_;
    } else if (c == '\n') {
      ++pos_;
      ++line_;
      line_start_ = pos_;
    } else if (c == '\r') {
      ++pos_;
      if (pos_ < n && input_[pos_] == '\n') ++pos_;  // CRLF is one line end
      ++line_;
      line_start_ = pos_;
    } else {
      return;
    }
  }
}

BvhToken BvhTokenizer::Next() {
  SkipBlanks();
  BvhToken token;
  token.line = line_;
  token.column = column();
  token.offset = pos_;
  if (pos_ >= input_.size()) return token;
  const std::size_t start = pos_;
  if (input_[pos_] == '{' || input_[pos_] == '}') {
    ++pos_;
  } else {
    while (pos_ < input_.size() && !IsTokenEnd(input_[pos_])) ++pos_;
  }
  token.text = input_.substr(start, pos_ - start);
  return token;
}

BvhToken BvhTokenizer::Peek() {
  const std::size_t pos = pos_;
  const int line = line_;
  const std::size_t line_start = line_start_;
  BvhToken token = Next();
  pos_ = pos;
  line_ = line;
  line_start_ = line_start;
  return token;
}

std::string_view BvhTokenizer::RestOfLineName(BvhToken* loc) {
  const std::size_t n = input_.size();
  while (pos_ < n && IsBvhBlank(input_[pos_])) ++pos_;
  loc->line = line_;
  loc->column = column();
  loc->offset = pos_;
  const std::size_t start = pos_;
  std::size_t end = pos_;  // one past the last non-blank byte of the name
  while (pos_ < n) {
    const char c = input_[pos_];
    if (c == '\n' || c == '\r' || c == '{') break;
    ++pos_;
    if (!IsBvhBlank(c)) end = pos_;
  }
  pos_ = end;  // leave trailing blanks and the line end to the next token
  loc->text = input_.substr(start, end - start);
  return loc->text;
}

BvhToken BvhTokenizer::EndLocation() {
  SkipBlanks();
  BvhToken token;
  token.line = line_;
  token.column = column();
  token.offset = pos_;
  return token;
}

}  // namespace mocap
