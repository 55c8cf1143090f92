#include "mocap/bvh_reader.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <limits>
#include <mutex>
#include <utility>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/parallel.h"
#include "mocap/channel_use.h"
#include "mocap/internal/bvh_number.h"
#include "mocap/pose.h"

namespace mocap {

namespace {

inline bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; }
inline bool IsLineEnd(char c) { return c == '\n' || c == '\r'; }

enum ByteClass : unsigned char { kOther, kBlank, kLineEnd };
constexpr auto kByteClass = [] {
  std::array<ByteClass, 256> table{};
  for (const char c : {' ', '\t', '\f', '\v'}) table[static_cast<unsigned char>(c)] = kBlank;
  for (const char c : {'\n', '\r'}) table[static_cast<unsigned char>(c)] = kLineEnd;
  return table;
}();

// Gives pages of a read-only file mapping back to the kernel once they are
// parsed (madvise MADV_DONTNEED), so a long capture's text never counts in
// the process's memory all at once; a later read of a released byte (an error
// message's token) faults the page in again from the page cache. A default
// one (in-memory text, which is the caller's) does nothing.
struct PageReleaser {
  const char* base = nullptr;  // start of the mapping; nullptr = release nothing
  std::size_t size = 0;        // bytes mapped

  // Releases the whole pages holding bytes of [base, end) from the page that
  // holds `begin` on: the caller has read everything before `end` (a page that
  // `end` cuts is kept; it goes with the next call).
  void Release(const char* begin, const char* end) const {
    if (base == nullptr || end <= begin) return;
    static const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    const std::size_t from = static_cast<std::size_t>(begin - base) / page * page;
    const std::size_t to = static_cast<std::size_t>(end - base) / page * page;
    if (to > from) {
      // Only advice: on failure the pages stay, which costs memory, not correctness.
      madvise(const_cast<char*>(base) + from, to - from, MADV_DONTNEED);
    }
  }
};

// Reads the frame data: one pass over the buffer, writing straight into the
// preallocated array. Line numbers are counted as we go; columns are computed
// only when an error is reported.
class MotionParser {
 public:
  MotionParser(std::string_view text, const BvhDocument& doc, PageReleaser release)
      : p_(text.data() + doc.motion_offset),
        end_(text.data() + text.size()),
        line_start_(text.data() + doc.motion_line_start),
        line_(doc.motion_line),
        doc_(doc),
        release_(release) {}

  base::Status Run(const BvhReadOptions& options, Motion* motion,
                   std::vector<base::Warning>* warnings) {
    const int num_channels = doc_.num_channels;
    motion->num_channels = num_channels;
    motion->frame_time_s = doc_.frame_time_s;
    const long long declared = doc_.declared_frames;
    if (num_channels == 0) {
      // Nothing to read per frame; frames are only a count.
      motion->num_frames = static_cast<int>(declared);
      motion->values.clear();
      SkipSpace();
      if (p_ != end_) WarnExtraLines(warnings, 0);
      return base::Status::Ok();
    }
    // A frame needs at least one digit and one separator per value.
    const std::size_t remaining = static_cast<std::size_t>(end_ - p_);
    const std::size_t per_frame_min = 2 * static_cast<std::size_t>(num_channels);
    const std::size_t fit = (remaining + 1) / per_frame_min;
    const std::size_t capacity = std::min(static_cast<std::size_t>(declared), fit);
    // reserve, not resize: the pages are touched once, by the copies below,
    // instead of being zeroed first. Each line is parsed into a small buffer
    // that stays in L1 and appended whole once it has exactly #C values.
    const std::size_t block_bytes = std::max<std::size_t>(options.block_bytes, 1);
    motion->values.clear();
    if (remaining >= options.parallel_min_bytes && static_cast<std::size_t>(declared) == capacity &&
        TryParseBlocks(num_channels, capacity, block_bytes, motion)) {
      return base::Status::Ok();
    }
    motion->values.clear();
    motion->values.reserve(capacity * static_cast<std::size_t>(num_channels));
    std::vector<float> line_values(static_cast<std::size_t>(num_channels));
    float* out = line_values.data();
    std::size_t frames = 0;
    const char* released = p_;  // everything before it was given back (release_)
    for (; frames < capacity; ++frames) {
      SkipSpace();
      if (p_ == end_) break;
      if (base::Status s = ParseLine(static_cast<long long>(frames) + 1, num_channels, out); !s)
        return s;
      motion->values.insert(motion->values.end(), out, out + num_channels);
      if (static_cast<std::size_t>(p_ - released) >= block_bytes) {
        release_.Release(released, p_);
        released = p_;
      }
    }
    if (static_cast<long long>(frames) < declared) {
      // Stopped by the size bound: whatever is left cannot be a whole frame,
      // so parsing it yields the precise error for that line.
      SkipSpace();
      if (p_ != end_) {
        std::vector<float> scratch(static_cast<std::size_t>(num_channels));
        if (base::Status s =
                ParseLine(static_cast<long long>(frames) + 1, num_channels, scratch.data());
            !s)
          return s;
      }
      const std::string counts = "'Frames:' declares " + std::to_string(declared) +
                                 " frames but the file holds " + std::to_string(frames);
      if (!options.allow_short_motion) {
        return base::MakeError(base::ErrorCode::kCountMismatch, Loc(p_), counts);
      }
      warnings->push_back(base::Warning{Loc(p_), counts + "; loading " + std::to_string(frames)});
    } else {
      SkipSpace();
      if (p_ != end_) WarnExtraLines(warnings, declared);
    }
    motion->num_frames = static_cast<int>(frames);
    return base::Status::Ok();
  }

 private:
  // Parses every frame from p_ to end_ into `values`, at most `max_frames`;
  // false on any error or on more frames (the caller then re-reads
  // sequentially for the exact message).
  bool ParseAllClean(int num_channels, std::size_t max_frames, std::vector<float>& values,
                     std::size_t& frames) {
    std::vector<float> line_values(static_cast<std::size_t>(num_channels));
    float* out = line_values.data();
    frames = 0;
    for (;;) {
      SkipSpace();
      if (p_ == end_) return true;
      if (frames == max_frames) return false;
      if (!ParseLine(static_cast<long long>(frames) + 1, num_channels, out)) return false;
      values.insert(values.end(), out, out + num_channels);
      ++frames;
    }
  }

  // The two-thread fast path (BvhReadOptions::parallel_min_bytes): the frame
  // data is cut into blocks of about block_bytes, each ending at a line end,
  // handed out in file order to this thread and a worker. Each parses its
  // block into a small buffer of its own, gives the block's pages back
  // (release_), then waits for its turn and appends the buffer to `motion`, so
  // the frames land in file order straight in the final array (reserved once
  // for `frames`) and at most one block's floats per thread are held on the
  // side. Taken only when every block parses cleanly and they hold exactly
  // `frames` frames together, i.e. exactly when the sequential pass would
  // succeed without a warning; false leaves the caller to run that pass.
  bool TryParseBlocks(int num_channels, std::size_t frames, std::size_t block_bytes,
                      Motion* motion) {
    motion->values.reserve(frames * static_cast<std::size_t>(num_channels));
    std::mutex mutex;
    std::condition_variable turn;
    const char* cursor = p_;      // start of the next block to hand out
    std::size_t next_ticket = 0;  // the next block's place in file order
    std::size_t appended = 0;     // blocks appended so far
    std::size_t total = 0;        // frames appended so far
    bool failed = false;
    const auto work = [&] {
      MotionParser parser = *this;
      // Room for a block's values (at least two bytes each) without regrowing;
      // only the pages written are ever resident.
      std::vector<float> values;
      values.reserve(block_bytes / 2 + static_cast<std::size_t>(num_channels));
      for (;;) {
        const char* begin = nullptr;
        const char* stop = nullptr;
        std::size_t ticket = 0;
        {
          const std::lock_guard<std::mutex> lock(mutex);
          if (failed || cursor == end_) return;
          begin = cursor;
          stop = begin + std::min(block_bytes, static_cast<std::size_t>(end_ - begin));
          while (stop != end_ && !IsLineEnd(*stop)) ++stop;
          while (stop != end_ && IsLineEnd(*stop)) ++stop;
          cursor = stop;
          ticket = next_ticket++;
        }
        // Line numbers are not known inside a block; they are only needed for
        // messages, which the sequential pass then gives.
        parser.p_ = begin;
        parser.end_ = stop;
        parser.line_start_ = begin;
        values.clear();
        std::size_t block_frames = 0;
        const bool ok = parser.ParseAllClean(num_channels, frames, values, block_frames);
        release_.Release(begin, stop);
        std::unique_lock<std::mutex> lock(mutex);
        turn.wait(lock, [&] { return failed || appended == ticket; });
        if (failed) return;
        if (!ok || total + block_frames > frames) {
          failed = true;
          turn.notify_all();
          return;
        }
        motion->values.insert(motion->values.end(), values.begin(), values.end());
        total += block_frames;
        ++appended;
        turn.notify_all();
      }
    };
    base::RunOnThreads(2, [&](int) { work(); });
    if (failed || total != frames) return false;
    motion->num_frames = static_cast<int>(frames);
    p_ = end_;
    return true;
  }

  base::FileLoc Loc(const char* where) const {
    return base::FileLoc{doc_.file_name, line_, static_cast<int>(where - line_start_) + 1, {}};
  }

  // Skips blanks and line ends, counting lines (LF, CRLF and CR each end one).
  void SkipSpace() {
    while (p_ != end_) {
      const char c = *p_;
      if (IsBlank(c)) {
        ++p_;
      } else if (c == '\n') {
        ++p_;
        ++line_;
        line_start_ = p_;
      } else if (c == '\r') {
        ++p_;
        if (p_ != end_ && *p_ == '\n') ++p_;
        ++line_;
        line_start_ = p_;
      } else {
        return;
      }
    }
  }

  // Parses one data line starting at a non-blank byte; leaves p_ at its line end.
  // The hot loop of the reader: works on local pointers (so they stay in
  // registers) and classifies bytes with one table lookup.
  base::Status ParseLine(long long frame, int num_channels, float* out) {
    const char* p = p_;
    const char* const end = end_;
    int count = 0;
    for (;;) {
      if (count == num_channels) [[unlikely]] {
        p_ = p;
        return TooMany(frame, num_channels, p);
      }
      const char* next = nullptr;
      const internal::NumberStatus s = internal::ParseBvhNumber(p, end, out[count], &next);
      if (s != internal::NumberStatus::kOk ||
          (next != end && kByteClass[static_cast<unsigned char>(*next)] == kOther)) [[unlikely]] {
        p_ = p;
        return BadNumber(frame, count, s, p);
      }
      ++count;
      p = next;
      while (p != end && kByteClass[static_cast<unsigned char>(*p)] == kBlank) ++p;
      if (p == end || kByteClass[static_cast<unsigned char>(*p)] == kLineEnd) break;
    }
    p_ = p;
    if (count != num_channels) [[unlikely]] {
      return base::MakeError(base::ErrorCode::kCountMismatch, Loc(p_),
                             "expected " + std::to_string(num_channels) + " values in frame " +
                                 std::to_string(frame) + ", found " + std::to_string(count));
    }
    return base::Status::Ok();
  }

  base::Error TooMany(long long frame, int num_channels, const char* extra) {
    int count = num_channels;
    const char* q = extra;
    while (q != end_ && !IsLineEnd(*q)) {
      while (q != end_ && IsBlank(*q)) ++q;
      if (q == end_ || IsLineEnd(*q)) break;
      ++count;
      while (q != end_ && !IsBlank(*q) && !IsLineEnd(*q)) ++q;
    }
    return base::MakeError(base::ErrorCode::kCountMismatch, Loc(extra),
                           "expected " + std::to_string(num_channels) + " values in frame " +
                               std::to_string(frame) + ", found " + std::to_string(count));
  }

  base::Error BadNumber(long long frame, int index, internal::NumberStatus s, const char* token) {
    const char* q = token;
    while (q != end_ && !IsBlank(*q) && !IsLineEnd(*q) && q - token < 40) ++q;
    const std::string found(token, static_cast<std::size_t>(q - token));
    const bool non_finite = s == internal::NumberStatus::kNonFinite;
    return base::MakeError(
        non_finite ? base::ErrorCode::kNonFinite : base::ErrorCode::kBadNumber, Loc(token),
        std::string(non_finite ? "expected a finite number" : "expected a number") + " for value " +
            std::to_string(index + 1) + " of frame " + std::to_string(frame) + ", found '" + found +
            "'");
  }

  void WarnExtraLines(std::vector<base::Warning>* warnings, long long declared) {
    const base::FileLoc first = Loc(p_);
    long long extra = 0;
    while (p_ != end_) {
      ++extra;
      while (p_ != end_ && !IsLineEnd(*p_)) ++p_;
      SkipSpace();
    }
    warnings->push_back(base::Warning{first, std::to_string(extra) + " data line(s) after the " +
                                                 std::to_string(declared) +
                                                 " frames 'Frames:' declares; ignored"});
  }

  const char* p_;
  const char* end_;
  const char* line_start_;
  int line_;
  const BvhDocument& doc_;
  PageReleaser release_;
};

glm::vec3 ZUpToYUp(const glm::vec3& v) { return {v.x, v.z, -v.y}; }

}  // namespace

UpAxis DetectBvhUpAxis(const Skeleton& skeleton) {
  auto vote = [](const glm::vec3& v, int* y_votes, int* z_votes) {
    const glm::vec3 a = glm::abs(v);
    if (a.y > a.x && a.y > a.z) ++*y_votes;
    if (a.z > a.x && a.z > a.y) ++*z_votes;
  };
  int y_votes = 0;
  int z_votes = 0;
  bool any = false;
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const std::size_t js = static_cast<std::size_t>(j);
    if (skeleton.parents[js] == kNoParent) continue;
    bool has_position = false;
    const JointChannels& c = skeleton.channels[js];
    for (int k = 0; k < c.count; ++k) {
      const ChannelType t = c.types[static_cast<std::size_t>(k)];
      has_position |= t == ChannelType::kXPosition || t == ChannelType::kYPosition ||
                      t == ChannelType::kZPosition;
    }
    if (has_position) continue;
    vote(skeleton.rest_translations[js], &y_votes, &z_votes);
    any = true;
  }
  for (const EndSite& e : skeleton.end_sites) {
    vote(e.offset, &y_votes, &z_votes);
    any = true;
  }
  if (!any) {
    for (int j = 0; j < skeleton.num_joints(); ++j) {
      const std::size_t js = static_cast<std::size_t>(j);
      if (skeleton.parents[js] != kNoParent)
        vote(skeleton.rest_translations[js], &y_votes, &z_votes);
    }
  }
  return z_votes > y_votes ? UpAxis::kZ : UpAxis::kY;
}

namespace {

// The limbs that hold the body up, as (hips, knee) joint pairs: the hips are
// the first joint below the first root with two or more children (passing
// joints the motion pulls away from their parents, Skeleton::channel_use); each child
// of it but the one with the most descendants (the spine) starts a limb (legs,
// a tail), whose knee is the first joint down it (first children) at least
// 40% of the limb's rest reach from the hips. Rest positions only, so the
// choice does not depend on any pose.
std::vector<std::pair<int, int>> HipsToKnees(const Skeleton& skeleton) {
  const int n = skeleton.num_joints();
  std::vector<std::vector<int>> children(static_cast<std::size_t>(n));
  std::vector<int> descendants(static_cast<std::size_t>(n), 0);
  std::vector<glm::vec3> rest(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) {
    const int p = skeleton.parents[static_cast<std::size_t>(j)];
    rest[static_cast<std::size_t>(j)] = skeleton.rest_translations[static_cast<std::size_t>(j)] +
                                        (p == kNoParent ? glm::vec3(0.0f) : rest[static_cast<std::size_t>(p)]);
    if (p != kNoParent) children[static_cast<std::size_t>(p)].push_back(j);
  }
  for (int j = n - 1; j >= 0; --j) {  // children come after their parents
    const int p = skeleton.parents[static_cast<std::size_t>(j)];
    if (p != kNoParent) descendants[static_cast<std::size_t>(p)] += descendants[static_cast<std::size_t>(j)] + 1;
  }
  std::vector<std::pair<int, int>> out;
  if (n == 0) return out;
  // What the motion pulls away from its parent (hips walking away from a root
  // on the floor, IK targets, props) is not a limb.
  const auto pulled = [&skeleton](int j) {
    return skeleton.channel_use.size() == skeleton.parents.size() &&
           (skeleton.channel_use[static_cast<std::size_t>(j)] & kJointStretches) != 0;
  };
  const auto heaviest = [&](int j) {
    int heavy = -1;
    for (int c : children[static_cast<std::size_t>(j)]) {
      if (heavy < 0 || descendants[static_cast<std::size_t>(c)] > descendants[static_cast<std::size_t>(heavy)]) heavy = c;
    }
    return heavy;
  };
  int hips = 0;
  while (children[static_cast<std::size_t>(hips)].size() == 1 || (heaviest(hips) >= 0 && pulled(heaviest(hips)))) {
    hips = heaviest(hips);
  }
  std::vector<int> limbs;
  for (int c : children[static_cast<std::size_t>(hips)]) {
    if (!pulled(c)) limbs.push_back(c);
  }
  if (limbs.size() < 2) return out;
  const int spine = heaviest(hips);
  const glm::vec3 h = rest[static_cast<std::size_t>(hips)];
  for (int c : limbs) {
    if (c == spine) continue;
    float reach = 0.0f;
    std::vector<int> stack = {c};
    while (!stack.empty()) {
      const int j = stack.back();
      stack.pop_back();
      reach = std::max(reach, glm::distance(rest[static_cast<std::size_t>(j)], h));
      for (int g : children[static_cast<std::size_t>(j)]) stack.push_back(g);
    }
    int knee = c;
    while (glm::distance(rest[static_cast<std::size_t>(knee)], h) < 0.4f * reach &&
           !children[static_cast<std::size_t>(knee)].empty()) {
      knee = children[static_cast<std::size_t>(knee)][0];
    }
    if (reach > 0.0f) out.emplace_back(hips, knee);
  }
  return out;
}

}  // namespace

UpAxis DetectBvhUpAxisFromPoses(const Skeleton& skeleton, const Motion& motion,
                                UpAxisSource* source) {
  constexpr int kSampleFrames = 32;
  const std::vector<std::pair<int, int>> thighs = HipsToKnees(skeleton);
  const std::size_t n = skeleton.rest_translations.size();
  std::vector<JointTransform> locals(n);
  std::vector<glm::mat4> model(n);
  int y_frames = 0;
  int z_frames = 0;
  const int samples = thighs.empty() ? 0 : std::min(motion.num_frames, kSampleFrames);
  for (int i = 0; i < samples; ++i) {
    const int f = samples > 1 ? static_cast<int>(std::int64_t{motion.num_frames - 1} * i / (samples - 1)) : 0;
    if (!LocalPoseJob{&skeleton, motion.frame(f), locals}.Run()) continue;
    if (!LocalToModelJob{skeleton.parents, locals, glm::mat4(1.0f), model}.Run()) continue;
    int y_votes = 0;
    int z_votes = 0;
    for (const auto& [hips, knee] : thighs) {
      const glm::vec3 a = glm::abs(glm::vec3(model[static_cast<std::size_t>(knee)][3] -
                                             model[static_cast<std::size_t>(hips)][3]));
      if (a.y > a.x && a.y > a.z) ++y_votes;
      if (a.z > a.x && a.z > a.y) ++z_votes;
    }
    if (y_votes > z_votes) ++y_frames;
    if (z_votes > y_votes) ++z_frames;
  }
  if (y_frames == z_frames) {
    if (source != nullptr) *source = UpAxisSource::kRestPose;
    return DetectBvhUpAxis(skeleton);
  }
  if (source != nullptr) *source = UpAxisSource::kAnimatedPoses;
  return z_frames > y_frames ? UpAxis::kZ : UpAxis::kY;
}

float RestHeight(const Skeleton& skeleton, UpAxis up) {
  const int axis = up == UpAxis::kY ? 1 : 2;
  std::vector<glm::vec3> model(skeleton.rest_translations.size());
  float lo = std::numeric_limits<float>::max();
  float hi = std::numeric_limits<float>::lowest();
  for (std::size_t j = 0; j < model.size(); ++j) {
    const int p = skeleton.parents[j];
    model[j] = skeleton.rest_translations[j] +
               (p == kNoParent ? glm::vec3(0.0f) : model[static_cast<std::size_t>(p)]);
    lo = std::min(lo, model[j][axis]);
    hi = std::max(hi, model[j][axis]);
  }
  for (const EndSite& e : skeleton.end_sites) {
    const float h = model[static_cast<std::size_t>(e.parent)][axis] + e.offset[axis];
    lo = std::min(lo, h);
    hi = std::max(hi, h);
  }
  return hi >= lo ? hi - lo : 0.0f;
}

float FirstFrameHeight(const Skeleton& skeleton, const Motion& motion, UpAxis up) {
  if (motion.num_frames < 1) return 0.0f;
  const std::size_t n = skeleton.rest_translations.size();
  std::vector<JointTransform> locals(n);
  std::vector<glm::mat4> model(n);
  if (!LocalPoseJob{&skeleton, motion.frame(0), locals}.Run()) return 0.0f;
  if (!LocalToModelJob{skeleton.parents, locals, glm::mat4(1.0f), model}.Run()) return 0.0f;
  const int axis = up == UpAxis::kY ? 1 : 2;
  float lo = std::numeric_limits<float>::max();
  float hi = std::numeric_limits<float>::lowest();
  for (const glm::mat4& m : model) {
    lo = std::min(lo, m[3][axis]);
    hi = std::max(hi, m[3][axis]);
  }
  for (const EndSite& e : skeleton.end_sites) {
    const float h = (model[static_cast<std::size_t>(e.parent)] * glm::vec4(e.offset, 1.0f))[axis];
    lo = std::min(lo, h);
    hi = std::max(hi, h);
  }
  return hi >= lo ? hi - lo : 0.0f;
}

float MetresPerUnit(std::string_view units) {
  return units == "m" ? 1.0f : units == "cm" ? 0.01f : units == "inch" ? 0.0254f : 0.0f;
}

const char* DetectUnits(float h) {
  if (h >= 0.5f && h <= 3.0f) return "m";
  if (h >= 40.0f && h < 100.0f) return "inch";
  if (h >= 100.0f && h <= 300.0f) return "cm";
  return "unknown";
}

void ScaleSkeletonAndMotion(float factor, Skeleton* skeleton, Motion* motion) {
  for (glm::vec3& t : skeleton->rest_translations) t *= factor;
  for (EndSite& e : skeleton->end_sites) e.offset *= factor;
  std::vector<int> columns;
  for (const JointChannels& c : skeleton->channels) {
    for (int k = 0; k < c.count; ++k) {
      const ChannelType t = c.types[static_cast<std::size_t>(k)];
      if (t == ChannelType::kXPosition || t == ChannelType::kYPosition ||
          t == ChannelType::kZPosition) {
        columns.push_back(static_cast<int>(c.first) + k);
      }
    }
  }
  for (int f = 0; f < motion->num_frames; ++f) {
    std::span<float> row = motion->frame(f);
    for (int c : columns) row[static_cast<std::size_t>(c)] *= factor;
  }
}

void ConvertZUpToYUp(Skeleton* skeleton, Motion* motion) {
  for (glm::vec3& t : skeleton->rest_translations) t = ZUpToYUp(t);
  for (EndSite& e : skeleton->end_sites) e.offset = ZUpToYUp(e.offset);
  std::vector<int> negate;
  for (JointChannels& c : skeleton->channels) {
    for (int k = 0; k < c.count; ++k) {
      ChannelType& t = c.types[static_cast<std::size_t>(k)];
      const int column = static_cast<int>(c.first) + k;
      switch (t) {
        case ChannelType::kYPosition:
          t = ChannelType::kZPosition;
          negate.push_back(column);
          break;
        case ChannelType::kZPosition:
          t = ChannelType::kYPosition;
          break;
        case ChannelType::kYRotation:
          t = ChannelType::kZRotation;
          negate.push_back(column);
          break;
        case ChannelType::kZRotation:
          t = ChannelType::kYRotation;
          break;
        default:
          break;
      }
    }
  }
  for (int f = 0; f < motion->num_frames; ++f) {
    std::span<float> row = motion->frame(f);
    for (int c : negate) row[static_cast<std::size_t>(c)] = -row[static_cast<std::size_t>(c)];
  }
  skeleton->info.up_axis = UpAxis::kY;
}

namespace {

// ParseBvh, with the pages of `text` given back as they are parsed when it is
// a file mapping (`release`).
base::Result<BvhFile> ParseBvhText(std::string_view text, const std::string& file_name,
                                   const BvhReadOptions& options, PageReleaser release) {
  if (!(options.scale >= 0.0f) || !std::isfinite(options.scale)) {
    return base::InvalidArgument(
        base::FileLoc{file_name, 0, 0, {}},
        "scale must be finite and >= 0 (0 = automatic), got " + std::to_string(options.scale));
  }
  // Windows tools sometimes write a UTF-8 byte order mark; it is not part of the grammar.
  if (text.size() >= 3 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.remove_prefix(3);
  base::Result<BvhDocument> document =
      ParseBvhHierarchy(text, file_name, {options.max_depth, options.max_joints});
  if (!document) return std::move(document).error();
  BvhFile file;
  file.warnings = std::move(document->warnings);
  base::Result<Skeleton> skeleton =
      BuildBvhSkeleton(*document, options.position_mode, &file.warnings);
  if (!skeleton) return std::move(skeleton).error();
  file.skeleton = std::move(skeleton).value();
  if (base::Status s =
          MotionParser(text, *document, release).Run(options, &file.motion, &file.warnings);
      !s)
    return s.error();

  file.skeleton.channel_use = ChannelUse(file.skeleton, file.motion);
  SkeletonInfo& info = file.skeleton.info;
  if (options.up_axis.has_value()) {
    info.up_axis = *options.up_axis;
    info.up_axis_source = UpAxisSource::kGiven;
  } else {
    info.up_axis = DetectBvhUpAxisFromPoses(file.skeleton, file.motion, &info.up_axis_source);
  }
  const float raw_height = RestHeight(file.skeleton, info.up_axis);
  // A rest pose need not stand upright (Bandai Namco's bones lie along X), so
  // the units come from the taller of the rest pose and the first frame.
  info.detected_units =
      DetectUnits(std::max(raw_height, FirstFrameHeight(file.skeleton, file.motion, info.up_axis)));
  float scale = options.scale;
  if (scale == 0.0f) {
    scale = MetresPerUnit(info.detected_units) > 0.0f ? MetresPerUnit(info.detected_units) : 1.0f;
    if (info.detected_units == std::string("unknown")) {
      file.warnings.push_back(base::Warning{base::FileLoc{file_name, 0, 0, {}},
                                            "units not recognised from a rest height of " +
                                                std::to_string(raw_height) +
                                                "; automatic scale left at 1"});
    }
  }
  if (scale != 1.0f) ScaleSkeletonAndMotion(scale, &file.skeleton, &file.motion);
  info.scale_applied = scale;
  info.rest_height = raw_height * scale;
  if (options.convert_to_y_up && info.up_axis == UpAxis::kZ)
    ConvertZUpToYUp(&file.skeleton, &file.motion);
  return file;
}

}  // namespace

base::Result<BvhFile> ParseBvh(std::string_view text, const std::string& file_name,
                               const BvhReadOptions& options) {
  return ParseBvhText(text, file_name, options, PageReleaser{});
}

namespace {

// A read-only view of a whole file: mmap'd, so the parser reads the page cache
// directly instead of a copy (the copy costs about a quarter of the parse time
// on an 80 MB file).
class MappedFile {
 public:
  MappedFile() = default;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile() {
    if (data_ != nullptr) munmap(data_, size_);
    if (fd_ >= 0) close(fd_);
  }

  base::Status Open(const std::string& path) {
    const base::FileLoc loc{path, 0, 0, {}};
    fd_ = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0)
      return base::MakeError(base::ErrorCode::kIo, loc,
                             std::string("cannot open the file: ") + std::strerror(errno));
    struct stat info {};
    if (fstat(fd_, &info) != 0 || !S_ISREG(info.st_mode)) {
      return base::MakeError(base::ErrorCode::kIo, loc, "not a regular file");
    }
    size_ = static_cast<std::size_t>(info.st_size);
    if (size_ == 0) return base::Status::Ok();
    void* data = mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd_, 0);
    if (data == MAP_FAILED)
      return base::MakeError(base::ErrorCode::kIo, loc,
                             std::string("cannot map the file: ") + std::strerror(errno));
    data_ = data;
    madvise(data_, size_, MADV_SEQUENTIAL);
    return base::Status::Ok();
  }

  // Gives parsed pages back (see PageReleaser); none for an empty file.
  PageReleaser releaser() const { return {static_cast<const char*>(data_), size_}; }

  std::string_view text() const {
    return data_ == nullptr ? std::string_view()
                            : std::string_view(static_cast<const char*>(data_), size_);
  }

 private:
  int fd_ = -1;
  void* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace

base::Result<BvhFile> ReadBvhFile(const std::string& path, const BvhReadOptions& options) {
  MappedFile file;
  if (base::Status s = file.Open(path); !s) return s.error();
  return ParseBvhText(file.text(), path, options, file.releaser());
}

}  // namespace mocap
