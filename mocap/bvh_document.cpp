#include "mocap/bvh_document.h"

#include <charconv>
#include <climits>
#include <unordered_map>
#include <unordered_set>

#include "mocap/bvh_tokenizer.h"
#include "mocap/internal/bvh_number.h"

namespace mocap {

namespace {

// True when `text` is well-formed UTF-8: no stray continuation byte, overlong
// form, surrogate or code point past U+10FFFF.
bool IsUtf8(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto b = static_cast<unsigned char>(text[i]);
    std::size_t more = 0;
    unsigned lo = 0x80, hi = 0xBF;  // the second byte's range (RFC 3629, section 4)
    if (b < 0x80) {
      more = 0;
    } else if (b >= 0xC2 && b <= 0xDF) {
      more = 1;
    } else if (b >= 0xE0 && b <= 0xEF) {
      more = 2;
      if (b == 0xE0) lo = 0xA0;
      if (b == 0xED) hi = 0x9F;
    } else if (b >= 0xF0 && b <= 0xF4) {
      more = 3;
      if (b == 0xF0) lo = 0x90;
      if (b == 0xF4) hi = 0x8F;
    } else {
      return false;
    }
    if (i + more >= text.size() && more > 0) return false;
    for (std::size_t k = 1; k <= more; ++k) {
      const auto c = static_cast<unsigned char>(text[i + k]);
      if (c < (k == 1 ? lo : 0x80u) || c > (k == 1 ? hi : 0xBFu)) return false;
    }
    i += more + 1;
  }
  return true;
}

// Each byte read as the Latin-1 (ISO 8859-1) character it names, in UTF-8.
std::string Latin1ToUtf8(std::string_view text) {
  std::string out;
  out.reserve(text.size() * 2);
  for (const char ch : text) {
    const auto b = static_cast<unsigned char>(ch);
    if (b < 0x80) {
      out += ch;
    } else {
      out += static_cast<char>(0xC0 | (b >> 6));
      out += static_cast<char>(0x80 | (b & 0x3F));
    }
  }
  return out;
}

// Shows a token in a message: quoted text, or "end of file".
std::string Found(const BvhToken& token) {
  if (token.empty()) return "end of file";
  std::string text(token.text.substr(0, 40));
  return "'" + text + (token.text.size() > 40 ? "...'" : "'");
}

bool ParseChannelName(std::string_view text, ChannelType* type) {
  static constexpr struct {
    std::string_view name;
    ChannelType type;
  } kNames[] = {
      {"Xposition", ChannelType::kXPosition}, {"Yposition", ChannelType::kYPosition},
      {"Zposition", ChannelType::kZPosition}, {"Xrotation", ChannelType::kXRotation},
      {"Yrotation", ChannelType::kYRotation}, {"Zrotation", ChannelType::kZRotation},
  };
  for (const auto& entry : kNames) {
    if (BvhKeywordEquals(text, entry.name)) {
      *type = entry.type;
      return true;
    }
  }
  return false;
}

// Splits "Key:value" glued tokens. Returns the part after the first ':' (may be empty).
std::string_view AfterColon(std::string_view token) {
  const std::size_t colon = token.find(':');
  return colon == std::string_view::npos ? std::string_view() : token.substr(colon + 1);
}

class HierarchyParser {
 public:
  HierarchyParser(std::string_view text, const std::string& file_name, const BvhParseLimits& limits)
      : tok_(text), limits_(limits) {
    doc_.file_name = file_name;
  }

  base::Result<BvhDocument> Run() {
    BvhToken t = tok_.Next();
    if (!BvhKeywordEquals(t.text, "HIERARCHY")) {
      return Fail(base::ErrorCode::kSyntax, t,
                  "expected 'HIERARCHY' at the start of the file, found " + Found(t));
    }
    for (;;) {
      t = tok_.Next();
      if (BvhKeywordEquals(t.text, "ROOT")) {
        if (base::Status s = ParseTree(t); !s) return s.error();
      } else if (BvhKeywordEquals(t.text, "MOTION") && !doc_.joints.empty()) {
        break;
      } else {
        return Fail(
            base::ErrorCode::kSyntax, t,
            std::string(doc_.joints.empty() ? "expected 'ROOT'" : "expected 'ROOT' or 'MOTION'") +
                ", found " + Found(t));
      }
    }
    if (base::Status s = ParseMotionHeader(); !s) return s.error();
    return std::move(doc_);
  }

 private:
  base::Error Fail(base::ErrorCode code, const BvhToken& where, std::string message) const {
    return base::MakeError(code, base::FileLoc{doc_.file_name, where.line, where.column, {}},
                           std::move(message));
  }

  base::Status ParseFloat(const BvhToken& t, const char* what, float* value) {
    if (t.empty() || t.text == "{" || t.text == "}") {
      return Fail(base::ErrorCode::kSyntax, t,
                  std::string("expected ") + what + ", found " + Found(t));
    }
    const char* next = nullptr;
    const char* end = t.text.data() + t.text.size();
    const internal::NumberStatus s = internal::ParseBvhNumber(t.text.data(), end, *value, &next);
    if (s == internal::NumberStatus::kNonFinite) {
      return Fail(base::ErrorCode::kNonFinite, t,
                  std::string("expected a finite ") + what + ", found " + Found(t));
    }
    if (s != internal::NumberStatus::kOk || next != end) {
      return Fail(base::ErrorCode::kBadNumber, t,
                  std::string("expected ") + what + ", found " + Found(t));
    }
    return base::Status::Ok();
  }

  base::Status ParseOffset(glm::vec3* offset) {
    static const char* const kWhat[3] = {"OFFSET x", "OFFSET y", "OFFSET z"};
    for (int i = 0; i < 3; ++i) {
      if (base::Status s = ParseFloat(tok_.Next(), kWhat[i], &(*offset)[i]); !s) return s;
    }
    return base::Status::Ok();
  }

  // Reads the name after ROOT/JOINT/End Site and the '{' that follows.
  base::Status ParseNameAndBrace(const BvhToken& keyword, bool name_required, std::string* name,
                                 BvhToken* name_loc) {
    tok_.RestOfLineName(name_loc);
    if (name_loc->text.empty()) {
      if (name_required) {
        return Fail(base::ErrorCode::kSyntax, *name_loc,
                    "expected a joint name after " + Found(keyword) + ", found end of line");
      }
    } else {
      *name = std::string(name_loc->text);
      // Names are UTF-8 everywhere they go (JSON, glTF); older tools wrote Latin-1.
      if (!IsUtf8(*name)) {
        *name = Latin1ToUtf8(name_loc->text);
        doc_.warnings.push_back(
            base::Warning{base::FileLoc{doc_.file_name, name_loc->line, name_loc->column, {}},
                          "name '" + *name + "' is not UTF-8; read as Latin-1"});
      }
    }
    const BvhToken brace = tok_.Next();
    if (brace.text != "{") {
      return Fail(base::ErrorCode::kSyntax, brace,
                  "expected '{' after " + (name->empty() ? Found(keyword) : "'" + *name + "'") +
                      ", found " + Found(brace));
    }
    return base::Status::Ok();
  }

  base::Status AddJoint(const BvhToken& keyword, int parent, int depth) {
    if (depth > limits_.max_depth) {
      return Fail(base::ErrorCode::kLimitExceeded, keyword,
                  "joint nesting deeper than the limit of " + std::to_string(limits_.max_depth));
    }
    if (static_cast<int>(doc_.joints.size()) >= limits_.max_joints) {
      return Fail(base::ErrorCode::kLimitExceeded, keyword,
                  "more joints than the limit of " + std::to_string(limits_.max_joints));
    }
    BvhJoint joint;
    joint.parent = parent;
    BvhToken name_loc;
    if (base::Status s = ParseNameAndBrace(keyword, true, &joint.name, &name_loc); !s) return s;
    joint.line = name_loc.line;
    joint.column = name_loc.column;
    doc_.joints.push_back(std::move(joint));
    return base::Status::Ok();
  }

  base::Status ParseChannels(const BvhToken& keyword, BvhJoint* joint) {
    const BvhToken count_tok = tok_.Next();
    int count = -1;
    const char* end = count_tok.text.data() + count_tok.text.size();
    const auto r = std::from_chars(count_tok.text.data(), end, count);
    if (count_tok.empty() || r.ec != std::errc() || r.ptr != end) {
      return Fail(base::ErrorCode::kBadNumber, count_tok,
                  "expected a channel count after CHANNELS, found " + Found(count_tok));
    }
    if (count < 0 || count > 6) {
      return Fail(base::ErrorCode::kBadChannel, count_tok,
                  "expected a channel count from 0 to 6, found " + Found(count_tok));
    }
    if (joint->num_channels > 0) {
      return Fail(base::ErrorCode::kBadChannel, keyword,
                  "second CHANNELS line for joint '" + joint->name + "'");
    }
    for (int i = 0; i < count; ++i) {
      const BvhToken t = tok_.Next();
      ChannelType type{};
      if (!ParseChannelName(t.text, &type)) {
        return Fail(base::ErrorCode::kBadChannel, t,
                    "expected a channel name (Xposition ... Zrotation), channel " +
                        std::to_string(i + 1) + " of " + std::to_string(count) + ", found " +
                        Found(t));
      }
      for (int k = 0; k < i; ++k) {
        if (joint->channels[k] == type) {
          return Fail(base::ErrorCode::kBadChannel, t, "duplicate channel " + Found(t));
        }
      }
      joint->channels[i] = type;
    }
    joint->num_channels = count;
    doc_.num_channels += count;
    return base::Status::Ok();
  }

  base::Status ParseEndSite(const BvhToken& end_kw, int parent) {
    const BvhToken site = tok_.Next();
    if (!BvhKeywordEquals(site.text, "Site")) {
      return Fail(base::ErrorCode::kSyntax, site,
                  "expected 'Site' after 'End', found " + Found(site));
    }
    BvhEndSite end_site;
    end_site.parent = parent;
    end_site.line = end_kw.line;
    end_site.column = end_kw.column;
    BvhToken name_loc;
    if (base::Status s = ParseNameAndBrace(end_kw, false, &end_site.name, &name_loc); !s) return s;
    if (end_site.name.empty()) end_site.name = "End Site";
    bool has_offset = false;
    for (;;) {
      const BvhToken t = tok_.Next();
      if (t.text == "}") break;
      if (BvhKeywordEquals(t.text, "OFFSET") && !has_offset) {
        if (base::Status s = ParseOffset(&end_site.offset); !s) return s;
        has_offset = true;
      } else {
        return Fail(base::ErrorCode::kSyntax, t,
                    std::string(has_offset ? "expected '}'" : "expected 'OFFSET'") +
                        " in End Site, found " + Found(t));
      }
    }
    doc_.end_sites.push_back(std::move(end_site));
    return base::Status::Ok();
  }

  // One ROOT and everything below it, with an explicit stack of open joints.
  base::Status ParseTree(const BvhToken& root_kw) {
    if (base::Status s = AddJoint(root_kw, kNoParent, 1); !s) return s;
    struct Open {
      int joint;
      bool has_offset;
      bool has_children;
    };
    std::vector<Open> stack{{static_cast<int>(doc_.joints.size()) - 1, false, false}};
    while (!stack.empty()) {
      Open& top = stack.back();
      BvhJoint& joint = doc_.joints[static_cast<std::size_t>(top.joint)];
      const BvhToken t = tok_.Next();
      if (t.text == "}") {
        if (!top.has_offset) {
          return Fail(base::ErrorCode::kSyntax, t,
                      "expected 'OFFSET' in joint '" + joint.name + "', found '}'");
        }
        stack.pop_back();
      } else if (BvhKeywordEquals(t.text, "OFFSET")) {
        if (top.has_offset)
          return Fail(base::ErrorCode::kSyntax, t, "second OFFSET in joint '" + joint.name + "'");
        if (base::Status s = ParseOffset(&joint.offset); !s) return s;
        top.has_offset = true;
      } else if (BvhKeywordEquals(t.text, "CHANNELS")) {
        if (top.has_children) {
          return Fail(base::ErrorCode::kSyntax, t,
                      "CHANNELS of joint '" + joint.name + "' must come before its children");
        }
        if (base::Status s = ParseChannels(t, &joint); !s) return s;
      } else if (BvhKeywordEquals(t.text, "JOINT")) {
        top.has_children = true;
        const int parent = top.joint;
        if (base::Status s = AddJoint(t, parent, static_cast<int>(stack.size()) + 1); !s) return s;
        stack.push_back({static_cast<int>(doc_.joints.size()) - 1, false, false});
      } else if (BvhKeywordEquals(t.text, "End")) {
        top.has_children = true;
        if (base::Status s = ParseEndSite(t, top.joint); !s) return s;
      } else {
        return Fail(base::ErrorCode::kSyntax, t,
                    "expected 'OFFSET', 'CHANNELS', 'JOINT', 'End Site' or '}' in joint '" +
                        joint.name + "', found " + Found(t));
      }
    }
    return base::Status::Ok();
  }

  // "Frames: N" and "Frame Time: T"; the value may be glued after the colon.
  base::Status ParseMotionHeader() {
    BvhToken t = tok_.Next();
    std::string_view value_text;
    BvhToken value_tok;
    if (BvhKeywordEquals(t.text.substr(0, 7), "Frames:")) {
      value_text = AfterColon(t.text);
      value_tok = t;
      value_tok.column += 7;
    } else if (BvhKeywordEquals(t.text, "Frames") && tok_.Peek().text.substr(0, 1) == ":") {
      const BvhToken colon = tok_.Next();
      value_text = colon.text.substr(1);
      value_tok = colon;
      value_tok.column += 1;
    } else {
      return Fail(base::ErrorCode::kSyntax, t,
                  "expected 'Frames:' after MOTION, found " + Found(t));
    }
    if (value_text.empty()) {
      value_tok = tok_.Next();
      value_text = value_tok.text;
    }
    doc_.frames_line = value_tok.line;
    doc_.frames_column = value_tok.column;
    long long frames = -1;
    const char* end = value_text.data() + value_text.size();
    const auto r = std::from_chars(value_text.data(), end, frames);
    if (value_text.empty() || r.ptr != end ||
        (r.ec != std::errc() && r.ec != std::errc::result_out_of_range)) {
      return Fail(base::ErrorCode::kBadNumber, value_tok,
                  "expected a frame count after 'Frames:', found " +
                      (value_text.empty() ? std::string("end of file")
                                          : "'" + std::string(value_text) + "'"));
    }
    if (r.ec == std::errc::result_out_of_range || frames > INT_MAX) {
      return Fail(base::ErrorCode::kLimitExceeded, value_tok,
                  "declared frame count " + std::string(value_text) +
                      " is larger than the limit of " + std::to_string(INT_MAX));
    }
    if (frames < 0) {
      return Fail(base::ErrorCode::kBadNumber, value_tok,
                  "expected a frame count of 0 or more, found " + std::to_string(frames));
    }
    doc_.declared_frames = frames;

    const BvhToken frame_kw = tok_.Peek();
    if (BvhKeywordEquals(frame_kw.text, "Frame")) {
      tok_.Next();
      const BvhToken time_kw = tok_.Next();
      if (!BvhKeywordEquals(time_kw.text.substr(0, 5), "Time:") &&
          !(BvhKeywordEquals(time_kw.text, "Time") && tok_.Peek().text.substr(0, 1) == ":")) {
        return Fail(base::ErrorCode::kSyntax, time_kw,
                    "expected 'Time:' after 'Frame', found " + Found(time_kw));
      }
      BvhToken time_value = time_kw;
      std::string_view text = AfterColon(time_kw.text);
      if (BvhKeywordEquals(time_kw.text, "Time")) {
        time_value = tok_.Next();
        text = time_value.text.substr(1);
        time_value.column += 1;
      } else {
        time_value.column += 5;
      }
      if (text.empty()) {
        time_value = tok_.Next();
        text = time_value.text;
      }
      double seconds = 0.0;
      const char* next = nullptr;
      const char* text_end = text.data() + text.size();
      const internal::NumberStatus s =
          internal::ParseBvhNumber(text.data(), text_end, seconds, &next);
      if (text.empty() || s == internal::NumberStatus::kBadNumber || next != text_end) {
        return Fail(
            base::ErrorCode::kBadNumber, time_value,
            "expected a frame time in seconds, found " +
                (text.empty() ? std::string("end of file") : "'" + std::string(text) + "'"));
      }
      if (s == internal::NumberStatus::kNonFinite || !(seconds > 0.0)) {
        return Fail(s == internal::NumberStatus::kNonFinite ? base::ErrorCode::kNonFinite
                                                            : base::ErrorCode::kBadNumber,
                    time_value,
                    "expected a positive, finite frame time, found '" + std::string(text) + "'");
      }
      doc_.frame_time_s = seconds;
      doc_.has_frame_time = true;
    } else {
      doc_.warnings.push_back(
          base::Warning{base::FileLoc{doc_.file_name, frame_kw.line, frame_kw.column, {}},
                        "no 'Frame Time:' line; using the default of 1/30 s"});
    }
    doc_.motion_offset = tok_.offset();
    doc_.motion_line = tok_.line();
    doc_.motion_line_start = tok_.offset() - static_cast<std::size_t>(tok_.column() - 1);
    return base::Status::Ok();
  }

  BvhTokenizer tok_;
  BvhParseLimits limits_;
  BvhDocument doc_;
};

}  // namespace

base::Result<BvhDocument> ParseBvhHierarchy(std::string_view text, const std::string& file_name,
                                            const BvhParseLimits& limits) {
  BvhParseLimits checked = limits;
  if (checked.max_joints > kMaxJoints || checked.max_joints < 1) checked.max_joints = kMaxJoints;
  if (checked.max_depth < 1) checked.max_depth = 1;
  return HierarchyParser(text, file_name, checked).Run();
}

base::Result<Skeleton> BuildBvhSkeleton(const BvhDocument& document,
                                        PositionChannelMode position_mode,
                                        std::vector<base::Warning>* warnings) {
  Skeleton skeleton;
  const std::size_t n = document.joints.size();
  skeleton.names.reserve(n);
  skeleton.parents.reserve(n);
  skeleton.rest_translations.reserve(n);
  skeleton.rest_rotations.assign(n, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  skeleton.rest_scales.assign(n, glm::vec3(1.0f));
  skeleton.channels.reserve(n);
  std::unordered_set<std::string> used;
  used.reserve(n * 2);
  for (const BvhJoint& j : document.joints) used.insert(j.name);
  std::unordered_map<std::string, int> seen;
  std::uint32_t first = 0;
  for (const BvhJoint& j : document.joints) {
    std::string name = j.name;
    if (seen[j.name]++ > 0) {
      // A later duplicate: pick the first free "name_k", k >= 2.
      for (int k = seen[j.name];; ++k) {
        std::string candidate = j.name + "_" + std::to_string(k);
        if (used.insert(candidate).second) {
          name = std::move(candidate);
          break;
        }
      }
      if (warnings != nullptr) {
        warnings->push_back(
            base::Warning{base::FileLoc{document.file_name, j.line, j.column, {}},
                          "duplicate joint name '" + j.name + "' renamed to '" + name + "'"});
      }
    }
    skeleton.names.push_back(std::move(name));
    skeleton.parents.push_back(static_cast<std::int16_t>(j.parent));
    skeleton.rest_translations.push_back(j.offset);
    JointChannels channels;
    channels.first = j.num_channels > 0 ? first : 0;
    channels.count = static_cast<std::uint8_t>(j.num_channels);
    for (int c = 0; c < j.num_channels; ++c)
      channels.types[static_cast<std::size_t>(c)] = j.channels[c];
    first += static_cast<std::uint32_t>(j.num_channels);
    skeleton.channels.push_back(channels);
  }
  for (const BvhEndSite& e : document.end_sites) {
    skeleton.end_sites.push_back(EndSite{e.parent, e.offset, e.name});
  }
  skeleton.num_channels = static_cast<int>(first);
  skeleton.position_mode = position_mode;
  skeleton.info.source_file = document.file_name;
  if (base::Status s = skeleton.Check(); !s) return s.error();
  return skeleton;
}

}  // namespace mocap
