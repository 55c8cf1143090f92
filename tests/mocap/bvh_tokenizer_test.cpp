// BVH tokenizer and document: token text and 1-based line:column for every
// kind of line end, braces glued to names, names with spaces; file locations
// kept in the as-parsed document.

#include "mocap/bvh_tokenizer.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mocap/bvh_document.h"

namespace {

struct Expected {
  std::string text;
  int line;
  int column;
};

std::vector<Expected> AllTokens(std::string_view input) {
  mocap::BvhTokenizer tokenizer(input);
  std::vector<Expected> out;
  for (mocap::BvhToken t = tokenizer.Next(); !t.empty(); t = tokenizer.Next()) {
    out.push_back({std::string(t.text), t.line, t.column});
  }
  return out;
}

void ExpectTokens(std::string_view input, const std::vector<Expected>& expected) {
  const std::vector<Expected> got = AllTokens(input);
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].text, expected[i].text) << i;
    EXPECT_EQ(got[i].line, expected[i].line) << got[i].text;
    EXPECT_EQ(got[i].column, expected[i].column) << got[i].text;
  }
}

TEST(BvhTokenizer, LineEndsOfEveryKind) {
  const std::vector<Expected> expected = {{"a", 1, 1}, {"bb", 2, 2}, {"c", 3, 1}, {"d", 5, 2}};
  ExpectTokens("a\n\tbb\nc\n\n d", expected);
  ExpectTokens("a\r\n\tbb\r\nc\r\n\r\n d", expected);
  ExpectTokens("a\r\tbb\rc\r\r d", expected);
  ExpectTokens("a\r\n\tbb\rc\n\r\n d", expected);  // mixed
}

TEST(BvhTokenizer, BracesAreTokensOfTheirOwn) {
  ExpectTokens("Hips{OFFSET}", {{"Hips", 1, 1}, {"{", 1, 5}, {"OFFSET", 1, 6}, {"}", 1, 12}});
}

TEST(BvhTokenizer, EndOfInputHasALocation) {
  mocap::BvhTokenizer tokenizer("x \n  ");
  EXPECT_EQ(tokenizer.Next().text, "x");
  const mocap::BvhToken end = tokenizer.Next();
  EXPECT_TRUE(end.empty());
  EXPECT_EQ(end.line, 2);
  EXPECT_EQ(end.column, 3);
}

TEST(BvhTokenizer, RestOfLineNameKeepsInnerSpaces) {
  mocap::BvhTokenizer tokenizer("JOINT  Left Up Leg \t{\nROOT\nJOINT a:b.c{");
  EXPECT_EQ(tokenizer.Next().text, "JOINT");
  mocap::BvhToken loc;
  EXPECT_EQ(tokenizer.RestOfLineName(&loc), "Left Up Leg");
  EXPECT_EQ(loc.column, 8);
  EXPECT_EQ(tokenizer.Next().text, "{");
  EXPECT_EQ(tokenizer.Next().text, "ROOT");
  EXPECT_EQ(tokenizer.RestOfLineName(&loc), "");
  EXPECT_EQ(tokenizer.Next().text, "JOINT");
  EXPECT_EQ(tokenizer.RestOfLineName(&loc), "a:b.c");
  EXPECT_EQ(loc.line, 3);
  EXPECT_EQ(tokenizer.Next().text, "{");
}

TEST(BvhTokenizer, PeekDoesNotConsume) {
  mocap::BvhTokenizer tokenizer("a\nb");
  EXPECT_EQ(tokenizer.Peek().text, "a");
  EXPECT_EQ(tokenizer.Next().text, "a");
  const mocap::BvhToken b = tokenizer.Peek();
  EXPECT_EQ(b.line, 2);
  EXPECT_EQ(tokenizer.Next().line, 2);
}

TEST(BvhKeyword, ComparesWithoutCase) {
  EXPECT_TRUE(mocap::BvhKeywordEquals("hIeRaRcHy", "HIERARCHY"));
  EXPECT_FALSE(mocap::BvhKeywordEquals("HIERARCH", "HIERARCHY"));
}

TEST(BvhDocument, KeepsFileLocationsAndMotionStart) {
  const std::string text =
      "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 1 Zrotation\n End Site\n {\n  OFFSET 0 1 "
      "0\n }\n}\n"
      "MOTION\nFrames: 1\nFrame Time: 0.5\n7\n";
  auto doc = mocap::ParseBvhHierarchy(text, "d.bvh");
  ASSERT_TRUE(doc.ok()) << doc.error().ToString();
  ASSERT_EQ(doc->joints.size(), 1u);
  EXPECT_EQ(doc->joints[0].line, 2);
  EXPECT_EQ(doc->joints[0].column, 6);
  ASSERT_EQ(doc->end_sites.size(), 1u);
  EXPECT_EQ(doc->end_sites[0].line, 6);
  EXPECT_EQ(doc->end_sites[0].column, 2);
  EXPECT_EQ(doc->declared_frames, 1);
  EXPECT_EQ(doc->frames_line, 12);
  EXPECT_EQ(doc->frame_time_s, 0.5);
  EXPECT_TRUE(doc->has_frame_time);
  EXPECT_EQ(doc->motion_line, 13);
  EXPECT_EQ(text.substr(doc->motion_offset), "\n7\n");
  EXPECT_EQ(text.substr(doc->motion_line_start, 11), "Frame Time:");
}

}  // namespace
