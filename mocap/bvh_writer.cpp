#include "mocap/bvh_writer.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace mocap {

namespace {

template <typename T>
void AppendNumber(std::string* out, T value) {
  char buffer[40];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, r.ptr);
}

void AppendVec(std::string* out, const glm::vec3& v) {
  for (int i = 0; i < 3; ++i) {
    out->push_back(' ');
    AppendNumber(out, v[i]);
  }
}

bool IsBvhChannel(ChannelType t) {
  return static_cast<int>(t) <= static_cast<int>(ChannelType::kZRotation);
}

base::Status CheckName(const std::string& name, const char* what) {
  const bool bad = name.empty() || name.find_first_of("{}\r\n") != std::string::npos ||
                   name.front() == ' ' || name.front() == '\t' || name.back() == ' ' ||
                   name.back() == '\t';
  if (bad) {
    return base::MakeError(base::ErrorCode::kUnsupported, {},
                           std::string(what) + " name '" + name + "' cannot be written to BVH");
  }
  return base::Status::Ok();
}

}  // namespace

base::Result<std::string> FormatBvh(const Skeleton& skeleton, const Motion& motion) {
  if (base::Status s = skeleton.Check(); !s) return s.error();
  const int n = skeleton.num_joints();
  if (motion.num_channels != skeleton.num_channels || motion.num_frames < 0 ||
      motion.values.size() != static_cast<std::size_t>(motion.num_frames) *
                                  static_cast<std::size_t>(motion.num_channels)) {
    return base::InvalidArgument("motion size does not match the skeleton's channels");
  }
  if (n == 0) return base::InvalidArgument("skeleton has no joints");
  std::vector<std::vector<int>> children(static_cast<std::size_t>(n));
  std::vector<std::vector<int>> end_sites(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) {
    const std::size_t js = static_cast<std::size_t>(j);
    if (base::Status s = CheckName(skeleton.names[js], "joint"); !s) return s.error();
    const JointChannels& c = skeleton.channels[js];
    if (c.count > 6)
      return base::MakeError(base::ErrorCode::kUnsupported, {},
                             "joint '" + skeleton.names[js] + "' has more than 6 channels");
    for (int k = 0; k < c.count; ++k) {
      if (!IsBvhChannel(c.types[static_cast<std::size_t>(k)])) {
        return base::MakeError(base::ErrorCode::kUnsupported, {},
                               "joint '" + skeleton.names[js] + "' has a " +
                                   ChannelTypeName(c.types[static_cast<std::size_t>(k)]) +
                                   " channel, which BVH cannot hold");
      }
    }
    const int p = skeleton.parents[js];
    if (p != kNoParent) children[static_cast<std::size_t>(p)].push_back(j);
  }
  for (std::size_t e = 0; e < skeleton.end_sites.size(); ++e) {
    if (base::Status s = CheckName(skeleton.end_sites[e].name, "end site"); !s) return s.error();
    end_sites[static_cast<std::size_t>(skeleton.end_sites[e].parent)].push_back(
        static_cast<int>(e));
  }

  std::string out;
  out.reserve(static_cast<std::size_t>(n) * 160 + motion.values.size() * 12 + 64);
  out += "HIERARCHY\n";
  std::vector<int> column_source;  // written column -> column in motion
  column_source.reserve(static_cast<std::size_t>(skeleton.num_channels));
  // Explicit stack: a value >= 0 opens that joint, ~j closes it.
  std::vector<int> stack;
  for (int r = n - 1; r >= 0; --r) {
    if (skeleton.parents[static_cast<std::size_t>(r)] == kNoParent) stack.push_back(r);
  }
  int depth = 0;
  while (!stack.empty()) {
    const int item = stack.back();
    stack.pop_back();
    if (item < 0) {
      --depth;
      out.append(static_cast<std::size_t>(depth), '\t');
      out += "}\n";
      continue;
    }
    const std::size_t js = static_cast<std::size_t>(item);
    const std::string indent(static_cast<std::size_t>(depth), '\t');
    out += indent + (skeleton.parents[js] == kNoParent ? "ROOT " : "JOINT ") + skeleton.names[js] +
           "\n";
    out += indent + "{\n" + indent + "\tOFFSET";
    AppendVec(&out, skeleton.rest_translations[js]);
    const JointChannels& c = skeleton.channels[js];
    out += "\n" + indent + "\tCHANNELS " + std::to_string(c.count);
    for (int k = 0; k < c.count; ++k) {
      out += ' ';
      out += ChannelTypeName(c.types[static_cast<std::size_t>(k)]);
      column_source.push_back(static_cast<int>(c.first) + k);
    }
    out += '\n';
    for (int e : end_sites[js]) {
      const EndSite& site = skeleton.end_sites[static_cast<std::size_t>(e)];
      out += indent + "\tEnd Site" + (site.name == "End Site" ? "" : " " + site.name) + "\n";
      out += indent + "\t{\n" + indent + "\t\tOFFSET";
      AppendVec(&out, site.offset);
      out += "\n" + indent + "\t}\n";
    }
    ++depth;
    stack.push_back(~item);
    const std::vector<int>& kids = children[js];
    for (auto it = kids.rbegin(); it != kids.rend(); ++it) stack.push_back(*it);
  }
  out += "MOTION\nFrames: " + std::to_string(motion.num_frames) + "\nFrame Time: ";
  AppendNumber(&out, motion.frame_time_s);
  out += '\n';
  for (int f = 0; f < motion.num_frames; ++f) {
    const std::span<const float> row = motion.frame(f);
    for (std::size_t k = 0; k < column_source.size(); ++k) {
      if (k > 0) out += ' ';
      AppendNumber(&out, row[static_cast<std::size_t>(column_source[k])]);
    }
    out += '\n';
  }
  return out;
}

base::Status WriteBvhFile(const std::string& path, const Skeleton& skeleton, const Motion& motion) {
  base::Result<std::string> text = FormatBvh(skeleton, motion);
  if (!text) return std::move(text).error();
  const std::string temp = path + ".tmp";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out || !out.write(text->data(), static_cast<std::streamsize>(text->size())) ||
        !out.flush()) {
      std::error_code ignored;
      std::filesystem::remove(temp, ignored);
      return base::MakeError(base::ErrorCode::kIo, base::FileLoc{temp, 0, 0, {}},
                             "cannot write the file");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    return base::MakeError(base::ErrorCode::kIo, base::FileLoc{path, 0, 0, {}},
                           "cannot rename the temporary file into place");
  }
  return base::Status::Ok();
}

}  // namespace mocap
