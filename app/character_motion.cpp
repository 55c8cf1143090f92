#include "app/character_motion.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "app/demo_data.h"
#include "mocap/retarget.h"

namespace app {

namespace {
constexpr std::uintmax_t kMaxJointMapBytes = 1u << 20;
}  // namespace

base::Result<deform::JointMapEntries> ReadJointMap(const std::string& path) {
  const base::FileLoc loc{path, 0, 0, {}};
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec || !std::filesystem::is_regular_file(path, ec)) {
    return base::MakeError(base::ErrorCode::kIo, loc,
                           "expected a joint map file (JSON), found none");
  }
  if (bytes > kMaxJointMapBytes) {
    return base::MakeError(
        base::ErrorCode::kLimitExceeded, loc,
        "expected a joint map of at most 1 MiB, found " + std::to_string(bytes) + " bytes");
  }
  std::ifstream in(path, std::ios::binary);
  std::string text(static_cast<std::size_t>(bytes), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (!in) return base::MakeError(base::ErrorCode::kIo, loc, "cannot read the joint map");
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    int line = 1, column = 1;
    const std::size_t at = e.id >= 100 && e.id < 200
                               ? static_cast<const nlohmann::json::parse_error&>(e).byte : 0;
    for (std::size_t i = 0; i + 1 < at && i < text.size(); ++i) {
      if (text[i] == '\n') ++line, column = 1;
      else ++column;
    }
    std::string what = e.what();
    const auto cut = what.rfind(": ");
    if (cut != std::string::npos) what = what.substr(cut + 2);
    return base::MakeError(base::ErrorCode::kSyntax, {path, at ? line : 0, at ? column : 0, {}},
                           "invalid JSON in the joint map: " + what);
  }
  if (!doc.is_object()) {
    return base::InvalidArgument(
        loc, "expected a joint map object {\"glTF joint\": \"BVH joint\", ...}, found " +
                 std::string(doc.type_name()));
  }
  deform::JointMapEntries out;
  for (const auto& [key, value] : doc.items()) {
    if (!value.is_string() && !value.is_null()) {
      return base::InvalidArgument(loc, "expected a BVH joint name or null for \"" + key +
                                            "\", found " + std::string(value.type_name()));
    }
    out.emplace_back(key, value.is_string() ? value.get<std::string>() : std::string());
  }
  return out;
}

base::Result<Character> MakeRetargetedCharacter(MotionSource&& character, MotionSource&& motion,
                                                const std::string& joint_map_file,
                                                RetargetReport* report) {
  const std::string model_file = character.skeleton.info.source_file;
  const std::string motion_file = motion.skeleton.info.source_file;
  if (!character.gltf) {
    return base::InvalidArgument(
        {model_file, 0, 0, {}},
        "expected a glTF or GLB character to drive with a separate motion, "
        "found a " +
            character.format + " file");
  }
  if (motion.format != "bvh") {
    return base::InvalidArgument({motion_file, 0, 0, {}},
                                 "expected a BVH motion, found a " + motion.format + " file");
  }
  deform::JointMapEntries overrides;
  if (!joint_map_file.empty()) {
    base::Result<deform::JointMapEntries> read = ReadJointMap(joint_map_file);
    if (!read.ok()) return std::move(read).error();
    overrides = std::move(*read);
  }
  base::Result<deform::HumanoidMatch> match =
      deform::MatchHumanoids(character.skeleton, motion.skeleton, motion.motion, overrides,
                             model_file, motion_file, joint_map_file);
  if (!match.ok()) return std::move(match).error();
  base::Result<mocap::RetargetedMotion> retargeted = mocap::ApplyRetargetPlan(
      character.skeleton, motion.skeleton, motion.motion, match->plan, motion_file);
  if (!retargeted.ok()) return std::move(retargeted).error();
  if (report != nullptr) {
    const mocap::RetargetPlan& plan = match->plan;
    *report = {match->method, match->source_pose, match->target_sides, match->source_sides,
               plan.translation_scale,
               character.skeleton.names[static_cast<std::size_t>(plan.target_root)],
               motion.skeleton.names[static_cast<std::size_t>(plan.source_root)], {}};
    for (int j = 0; j < character.skeleton.num_joints(); ++j) {
      const int b = plan.source_of_target[static_cast<std::size_t>(j)];
      report->joints.emplace_back(character.skeleton.names[static_cast<std::size_t>(j)],
                                  b >= 0 ? motion.skeleton.names[static_cast<std::size_t>(b)] : "");
    }
  }
  for (base::Warning& w : match->warnings) retargeted->warnings.push_back(std::move(w));
  character.skeleton = std::move(retargeted->skeleton);
  character.motion = std::move(retargeted->motion);
  for (base::Warning& w : motion.warnings) character.warnings.push_back(std::move(w));
  for (base::Warning& w : retargeted->warnings) character.warnings.push_back(std::move(w));
  return MakeCharacter(std::move(character));
}

base::Result<Character> LoadCommandCharacter(const std::string& input, const std::string& motion,
                                             bool quiet, std::optional<mocap::UpAxis> up,
                                             const std::string& joint_map_file,
                                             RetargetReport* report, BodyKind body) {
  MotionSourceOptions load;
  load.y_up = true;  // frames are rendered Y-up with the ground at the feet
  load.up = up;
  base::Result<MotionSource> src = input.empty() ? LoadBvhText(DemoBvhText(), "demo_walk.bvh", load)
                                                 : LoadMotionSource(input, load);
  if (!src.ok()) return std::move(src).error();
  const auto print = [quiet](const std::vector<base::Warning>& warnings, std::size_t from) {
    if (quiet) return;
    for (std::size_t i = from; i < warnings.size(); ++i) {
      std::fprintf(stderr, "%s\n", warnings[i].ToString().c_str());
    }
  };
  print(src->warnings, 0);
  if (motion.empty() && !joint_map_file.empty()) {
    return base::InvalidArgument(
        {joint_map_file, 0, 0, {}},
        "expected a BVH motion (--motion) for the joint map to apply to, found none");
  }
  if (motion.empty()) return MakeCharacter(std::move(*src), {}, body);
  base::Result<MotionSource> bvh = LoadMotionSource(motion, load);
  if (!bvh.ok()) return std::move(bvh).error();
  const std::size_t printed = src->warnings.size();  // the glTF's, printed above
  base::Result<Character> character =
      MakeRetargetedCharacter(std::move(*src), std::move(*bvh), joint_map_file, report);
  if (character.ok()) print(character->warnings, printed);
  return character;
}

}  // namespace app
