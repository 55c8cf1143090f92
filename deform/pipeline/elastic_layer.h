#pragma once
// The elastic layer dE of the per-frame pipeline (ALGORITHMS.md 0 step 2 and
// 6): one damped mass-spring network (deform/elastic/mass_spring.h) per elastic patch,
// driven by the kinematics of its driving joint, its state carried from frame
// to frame.
//
// Chunk consistency: the state at motion time t is a function of t alone, not
// of the frames asked for before. Every network's fixed-step grid is anchored
// at the motion's start: after a reset the layer simulates preroll_s at the
// first frame's kinematics, then from t = 0 forward to the requested time (in
// pieces shorter than the network's time-gap reset, so it never resets on its
// own); the output is interpolated between the last two steps. Asking for an
// earlier time than the last one (a jump back, e.g. after the camera pre-pass)
// resets and re-simulates from the start, which costs microseconds per
// simulated frame. So frames A:B of a render equal the same frames of a 0:B
// render bit for bit, whatever the thread count (the layer is single-threaded).

#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "base/error.h"
#include "deform/elastic/mass_spring.h"
#include "deform/patch/patch_layer.h"
#include "mocap/kinematics.h"

namespace deform {

struct Character;  // deform/pipeline/character.h

// One elastic patch, resolved on a character.
struct ElasticPatchSpec {
  int patch = 0;            // index of the patch in the pipeline's patch list
  int joint = 0;            // driving joint (skeleton index)
  double cutoff_hz = 10.0;  // low-pass of the joint paths before differencing; 0 = off
  MassSpringParams params;  // with units_per_metre resolved (> 0)
};

// What one elastic patch did, for reports and tests.
struct ElasticPatchReport {
  int patch = 0;                      // pipeline patch index
  int joint = 0;                      // driving joint
  double time_step_s = 0.0;           // h after the step rule
  float max_displacement = 0.0f;      // e_max (model units)
  float displacement = 0.0f;          // largest |e| of the last output (model units)
  MassSpringCounters counters;        // limits applied since the last restart from t = 0
  std::vector<std::string> messages;  // step-rule notes of the network
};

class ElasticLayer {
 public:
  // Builds the networks: rest control points in the driving joint's bind frame
  // (BindModelFromJoint), the kinematics of the whole motion (smoothed at
  // cutoff_hz first), the step rule from the joint's largest angular speed.
  // Errors: kInvalidArgument for a motion without frames, a patch index out of
  // range, a grid beyond 16 x 16 or parameters the network refuses (with
  // "patches[i].elastic" as the field path).
  static base::Result<std::unique_ptr<ElasticLayer>> Create(const Character& character,
                                                            std::span<const PatchSetup> patches,
                                                            std::vector<ElasticPatchSpec> specs);

  // Advances every network to `time_s` (clamped to the motion) and writes each
  // elastic patch's displacement in model space, R_drv(t) e (#M x #N), into
  // displacements[spec.patch] (resized; the other entries are untouched).
  // model_from_joint: this frame's #J joint matrices (R_drv from them).
  base::Status Advance(double time_s, std::span<const glm::mat4> model_from_joint,
                       std::vector<std::vector<glm::vec3>>& displacements);

  std::vector<ElasticPatchReport> Report() const;
  int num_patches() const { return static_cast<int>(patches_.size()); }

 private:
  struct Patch {
    ElasticPatchSpec spec;
    MassSpringNetwork network;
    MassSpringState state;
    MassSpringCounters baseline;   // counters at the last restart
    std::vector<glm::vec3> local;  // #M x #N displacement in the joint frame
    int kinematics = 0;            // index into kinematics_
    int slot = 0;                  // column of spec.joint in that table
    float displacement = 0.0f;
  };
  // The driving joints sharing one cutoff, and their kinematics only.
  struct Kinematics {
    double cutoff_hz = 0.0;
    std::vector<int> joints;                     // #D distinct skeleton joints
    std::vector<mocap::JointKinematics> frames;  // #F x #D, column d = joints[d]
  };
  base::Status RunAll(double time_s);

  const Character* character_ = nullptr;
  std::vector<Patch> patches_;
  std::vector<Kinematics> kinematics_;
  bool started_ = false;
  double time_s_ = 0.0;  // time of the last output
  double duration_s_ = 0.0;
  double piece_s_ = 0.25;  // longest single advance (below every max_time_gap_s)
};

}  // namespace deform
