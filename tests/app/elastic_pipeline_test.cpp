// The elastic layer wired into the product (issue 7): rig files with
// patches[].elastic through FramePipeline and `patchskin render`. The sample rig
// belly_jump.json jiggles after the jump's landing and settles while the body
// stands; the state is a function of time alone (any frame order, range or
// thread count gives the same frames); a real capture played for 10,000 frames
// stays finite and bounded; a glitchy capture is limited and says so.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "deform/pipeline/elastic_layer.h"
#include "mocap/bvh_writer.h"
#include "tools/synthetic.h"
#include "support/data_paths.h"
#include "support/elastic_rig.h"
#include "support/run_process.h"
#include "support/tolerances.h"

namespace {

namespace fs = std::filesystem;
using testsupport::LoadRigPipeline;
using testsupport::LoadSampleRig;
using testsupport::SampleDataPath;
using testsupport::kElasticSettledFraction;
using testsupport::kElasticVisiblePeakCm;
using testsupport::kPositionTol;

bool Finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Largest |a - b| over the vertices.
float MaxDifference(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  float d = 0.0f;
  for (std::size_t v = 0; v < a.size(); ++v) d = std::max(d, glm::length(a[v] - b[v]));
  return d;
}

TEST(ElasticPipeline, SampleBellyJigglesAfterLandingThenSettles) {
  testsupport::RigPipeline l = LoadSampleRig("belly_jump.json");
  ASSERT_FALSE(HasFailure());
  const mocap::Motion& m = l.character->motion;
  const synthetic::JumpTimeline jump = synthetic::MakeJumpTimeline({});
  const double dt = m.frame_time_s;
  std::vector<float> e(static_cast<std::size_t>(m.num_frames));
  deform::DeformedFrame layered, global;
  float e_max = 0.0f;
  for (int f = 0; f < m.num_frames; ++f) {
    ASSERT_TRUE(l.layered->Evaluate(f * dt, layered).ok());
    ASSERT_TRUE(l.global->Evaluate(f * dt, global).ok());
    const std::vector<deform::ElasticPatchReport> report = l.layered->elastic_report();
    ASSERT_EQ(report.size(), 1u);
    e[static_cast<std::size_t>(f)] = report[0].displacement;
    e_max = report[0].max_displacement;
    // The mesh moves with the control points: a vertex is a convex B-spline
    // combination of them, blended with the global result, so it never moves
    // further than the largest control displacement.
    EXPECT_LE(MaxDifference(layered.positions, global.positions),
              report[0].displacement + kPositionTol)
        << "frame " << f;
    EXPECT_LE(report[0].displacement, e_max + kPositionTol) << "frame " << f;
    if (f == m.num_frames - 1) {
      const deform::MassSpringCounters& c = report[0].counters;
      EXPECT_EQ(c.any_limit(), 0)  // the sample's defaults need no limit
          << c.acceleration_clamps << " " << c.displacement_clamps << " " << c.non_finite_inputs;
    }
  }
  auto window_max = [&](double t0, double t1) {
    float peak = 0.0f;
    for (int f = static_cast<int>(std::ceil(t0 / dt)); f <= static_cast<int>(t1 / dt); ++f) {
      if (f >= 0 && f < m.num_frames) peak = std::max(peak, e[static_cast<std::size_t>(f)]);
    }
    return peak;
  };
  // The landing jiggles the belly visibly (model units are cm).
  const float landing = window_max(jump.touchdown_s, jump.touchdown_s + 0.5);
  EXPECT_GT(landing, kElasticVisiblePeakCm);
  // Still before the crouch: the preroll settled the network, nothing moves.
  EXPECT_LT(window_max(0.0, jump.crouch_start_s - 0.1), kPositionTol);
  // After the motion stops (the jump ends, the body stands 1.5 s) the energy
  // decays: every half-second window rings less than the one before, and the
  // last is a small fraction of the landing peak.
  const double still = jump.end_s + 0.1;
  float previous = window_max(still, still + 0.5);
  for (double t = still + 0.5; t + 0.5 <= m.duration_s() + 1e-9; t += 0.5) {
    const float now = window_max(t, t + 0.5);
    EXPECT_LT(now, previous) << "window from " << t << " s";
    previous = now;
  }
  EXPECT_LT(window_max(m.duration_s() - 0.3, m.duration_s()), kElasticSettledFraction * landing);
}

TEST(ElasticPipeline, FramesDependOnTimeAloneWhateverTheOrderRangeOrThreads) {
  testsupport::RigPipeline whole = LoadSampleRig("belly_jump.json");
  testsupport::RigPipeline chunk = LoadSampleRig("belly_jump.json", 2);
  ASSERT_FALSE(HasFailure());
  const double dt = whole.character->motion.frame_time_s;
  std::vector<std::vector<glm::vec3>> expected;
  deform::DeformedFrame frame;
  for (int f = 0; f <= 60; ++f) {
    ASSERT_TRUE(whole.layered->Evaluate(f * dt, frame).ok());
    if (f >= 40) expected.push_back(frame.positions);
  }
  // Out of order first (a camera pre-pass), then the chunk 40..60.
  for (int f : {90, 10, 55}) ASSERT_TRUE(chunk.layered->Evaluate(f * dt, frame).ok());
  for (int f = 40; f <= 60; ++f) {
    ASSERT_TRUE(chunk.layered->Evaluate(f * dt, frame).ok());
    ASSERT_EQ(frame.positions.size(), expected[static_cast<std::size_t>(f - 40)].size());
    EXPECT_TRUE(frame.positions == expected[static_cast<std::size_t>(f - 40)]) << "frame " << f;
  }
}

std::vector<std::string> RenderArgs(const fs::path& rig, const fs::path& out,
                                    const std::string& frames, const std::string& threads) {
  return {"render", rig.string(), "--frames", frames, "--threads", threads, "--supersample", "1",
          "--quiet", "--no-video", "--no-sheet", "--out", (out / "f_####.png").string()};
}

TEST(ElasticPipeline, ChunkedRenderGivesTheSameBytesAsTheWholeRange) {
  const fs::path d = testsupport::FreshOutputDir("elastic_pipeline/chunked");
  const fs::path rig = SampleDataPath("belly_jump.json");
  for (const auto& [name, frames, threads] :
       {std::tuple{"whole", "0:19", "1"}, std::tuple{"chunk", "10:19", "1"},
        std::tuple{"threads", "10:19", "2"}}) {
    const testsupport::ProcessResult r =
        testsupport::RunPatchskin(RenderArgs(rig, d / name, frames, threads), d / "logs" / name);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  for (int f = 10; f <= 19; ++f) {
    const std::string file = "f_00" + std::to_string(f) + ".png";
    const std::string whole = testsupport::SlurpFile(d / "whole" / file);
    ASSERT_FALSE(whole.empty()) << file;
    EXPECT_TRUE(whole == testsupport::SlurpFile(d / "chunk" / file)) << file;
    EXPECT_TRUE(whole == testsupport::SlurpFile(d / "threads" / file)) << file;
  }
}

// The sample belly rig with its elastic object replaced by `elastic` (JSON).
app::Rig BellyRig(const std::string& motion, const std::string& elastic) {
  auto rig = app::ParseRig(R"({"character": "mannequin", "motion": {"file": ")" + motion +
                               R"("}, "patches": [{"name": "belly",
      "region": {"view": "front", "rect": [0.44, 0.42, 0.56, 0.52]}, "parametrization": "plane",
      "grid": [5, 5], "elastic": )" + elastic + "}]}",
                           "belly.json");
  EXPECT_TRUE(rig.ok()) << rig.error().ToString();
  return *rig;
}

TEST(ElasticPipeline, TenThousandFramesOfARealCaptureStayFiniteAndBounded) {
  const fs::path bvh = testsupport::SharedDataPath("bvh/cmu_cgspeed/01_01.bvh");
  PATCHSKIN_REQUIRE_SHARED_FILE(bvh);
  // 01_01 (22.9 s at 120 fps) played forwards, backwards, forwards... to 10,000
  // frames: real capture noise plus a velocity reversal at every turn.
  constexpr int kFrames = 10000;
  testsupport::RigPipeline l =
      LoadRigPipeline(BellyRig(bvh.string(), "{}"), 1, [](app::MotionSource& s) {
        mocap::Motion& m = s.motion;
        const std::size_t nc = static_cast<std::size_t>(m.num_channels);
        std::vector<float> values;
        values.reserve(nc * kFrames);
        for (int k = 0; static_cast<int>(values.size() / nc) < kFrames; ++k) {
          const int period = 2 * (m.num_frames - 1);
          const int phase = k % period;
          const int f = phase < m.num_frames ? phase : period - phase;
          const auto row = m.frame(f);
          values.insert(values.end(), row.begin(), row.end());
        }
        m.values = std::move(values);
        m.num_frames = kFrames;
      });
  ASSERT_FALSE(HasFailure());
  const mocap::Motion& m = l.character->motion;
  ASSERT_EQ(m.num_frames, kFrames);
  deform::DeformedFrame frame;
  float peak = 0.0f;
  for (int f = 0; f < kFrames; ++f) {
    ASSERT_TRUE(l.layered->Evaluate(f * m.frame_time_s, frame).ok()) << f;
    const deform::ElasticPatchReport r = l.layered->elastic_report().at(0);
    ASSERT_TRUE(std::isfinite(r.displacement)) << "frame " << f;
    ASSERT_LE(r.displacement, r.max_displacement + kPositionTol) << "frame " << f;
    peak = std::max(peak, r.displacement);
    if (f % 500 == 0) {
      for (const glm::vec3& p : frame.positions) ASSERT_TRUE(Finite(p)) << "frame " << f;
    }
  }
  const deform::ElasticPatchReport r = l.layered->elastic_report().at(0);
  EXPECT_EQ(r.counters.non_finite_resets, 0);
  EXPECT_GT(peak, 0.0f);  // it did move
  std::printf("01_01 x 10000 frames: peak |e| %.3f of e_max %.3f, limits %lld (acc %lld, disp %lld)\n",
              peak, r.max_displacement, static_cast<long long>(r.counters.any_limit()),
              static_cast<long long>(r.counters.acceleration_clamps),
              static_cast<long long>(r.counters.displacement_clamps));
}

// The jump with the hips lifted `lift_cm` for one frame (a capture glitch):
// a second difference of 2 x lift / h^2, above 1000 m/s^2 at 30 fps.
constexpr int kGlitchFrame = 60;
constexpr float kGlitchLiftCm = 60.0f;  // 2 * 0.6 m * 900 / s^2 = 1080 m/s^2

void AddGlitch(mocap::Motion& m, const mocap::Skeleton& s) {
  const int hips = s.FindJoint("Hips");
  const mocap::JointChannels& ch = s.channels[static_cast<std::size_t>(hips)];
  for (int k = 0; k < ch.count; ++k) {
    if (ch.types[static_cast<std::size_t>(k)] == mocap::ChannelType::kYPosition) {
      m.frame(kGlitchFrame)[ch.first + static_cast<std::uint32_t>(k)] += kGlitchLiftCm;
    }
  }
}

TEST(ElasticPipeline, AGlitchyCaptureIsLimitedAndReported) {
  const std::string jump = SampleDataPath("jump.bvh").string();
  testsupport::RigPipeline l = LoadRigPipeline(BellyRig(jump, R"({"cutoff_hz": 0})"), 1,
                                               [](app::MotionSource& s) {
                                                 AddGlitch(s.motion, s.skeleton);
                                               });
  ASSERT_FALSE(HasFailure());
  const mocap::Motion& m = l.character->motion;
  deform::DeformedFrame frame;
  for (int f = 0; f < m.num_frames; ++f) {
    ASSERT_TRUE(l.layered->Evaluate(f * m.frame_time_s, frame).ok());
    const deform::ElasticPatchReport r = l.layered->elastic_report().at(0);
    ASSERT_TRUE(std::isfinite(r.displacement));
    ASSERT_LE(r.displacement, r.max_displacement + kPositionTol) << "frame " << f;
  }
  EXPECT_GT(l.layered->elastic_report().at(0).counters.acceleration_clamps, 0);

  // The command says so on stderr (and still renders).
  const fs::path d = testsupport::FreshOutputDir("elastic_pipeline/glitch");
  auto source = app::LoadMotionSource(jump, {});
  ASSERT_TRUE(source.ok());
  AddGlitch(source->motion, source->skeleton);
  ASSERT_TRUE(mocap::WriteBvhFile((d / "glitch.bvh").string(), source->skeleton, source->motion).ok());
  std::ofstream(d / "glitch.json")
      << R"({"character": "mannequin", "motion": {"file": "glitch.bvh"}, "patches": [{"name":
      "belly", "region": {"joint": "Spine1", "radius": 16, "side": [0, 0, 1],
      "half_angle_deg": 70}, "elastic": {"cutoff_hz": 0}}], "render": {"size": [64, 36]}})";
  const testsupport::ProcessResult r = testsupport::RunPatchskin(
      RenderArgs(d / "glitch.json", d / "frames", "62:62", "1"), d / "logs");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: elastic patch \"belly\" was limited: "), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("0 acceleration clamps"), std::string::npos) << r.err;
}

}  // namespace
