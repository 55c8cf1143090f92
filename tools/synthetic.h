#pragma once
// Deterministic procedural skeletons and motions for tests, samples and the
// demo. Nothing here reads files or uses random numbers: the same call always
// gives the same bits.
//
// Humanoid conventions (like a real capture): centimetres, Y up, the character
// faces +Z, its left side is +X. Rest pose is a T-pose standing on the ground
// plane y = 0 (toes at y = 1, ankles at y = 8, head top at y = 172). Every joint
// has three rotation channels in ZXY order (R = Rz * Rx * Ry, degrees); the root
// (Hips) also has Xposition Yposition Zposition first, which replace its offset.
// Joints (24): Hips, Spine, Spine1, Spine2, Neck, Head, {Left,Right}Shoulder,
// {Left,Right}Arm, {Left,Right}ForeArm, {Left,Right}Hand, {Left,Right}HandIndex1,
// {Left,Right}UpLeg, {Left,Right}Leg, {Left,Right}Foot, {Left,Right}ToeBase; end
// sites above the head, past the index fingers and in front of the toes.
//
// The motion generators take the skeleton they write for and look joints up by
// name, so they also fill a humanoid with other channel orders (Euler channels
// are extracted from the intended joint rotations in each joint's own order,
// relative to its rest rotation). They return kNotFound naming the first missing
// joint, and kInvalidArgument for a non-positive frame time or duration.

#include "base/error.h"
#include "mocap/motion.h"
#include "mocap/skeleton.h"

namespace synthetic {

// Standard gravity in the humanoid's units (cm/s^2), used by the jump.
inline constexpr double kGravityCmPerS2 = 981.0;

// The humanoid described above, in its T-pose rest.
mocap::Skeleton MakeHumanoidSkeleton();

// A looping walk cycle at constant speed along +Z. Each ankle follows a
// prescribed path relative to its hip joint and the legs are solved by two-bone
// IK, so a stance foot stays exactly planted (no sliding) and flat:
// - stance (duty 60% of the cycle, so both feet are down 20% of it): the ankle
//   moves back by step_length_cm at the walking speed step_length_cm / (0.6 cycle_s);
// - swing: a C1 cubic forward (zero ground speed at lift-off and touch-down)
//   with a sin^2 lift of foot_lift_cm; the knee peaks near 60 degrees.
// Hips bob 2 cm (highest at mid-stance, vertical acceleration ~0.3 g) and sway
// 2 cm over the stance foot (legs tilt to keep the feet planted); the chest
// counter-twists with the arm swing (spine twist; neck and head undo it);
// arms hang 75 degrees below horizontal and swing against the same-side leg,
// the elbow bending more as the arm comes forward. Frame k + cycle frames has
// the same joint rotations as frame k (the hips have moved one stride).
// Duration num_cycles * cycle_s, the end frame excluded.
struct WalkOptions {
  double frame_time_s = 1.0 / 30.0;
  int num_cycles = 3;            // >= 1
  double cycle_s = 1.0;          // one left and one right step
  double step_length_cm = 56.0;  // ankle travel during stance, in (0, 60]
  double foot_lift_cm = 10.0;    // ankle lift at mid-swing, in [0, 30]
  float arm_swing_deg = 15.0f;   // upper-arm swing amplitude
  float elbow_peak_deg = 45.0f;  // elbow flexion with the arm fully forward (<= 120)
};
base::Result<mocap::Motion> MakeWalkMotion(const mocap::Skeleton& humanoid,
                                           const WalkOptions& options = {});

// Elbows (both, arms in T-pose, forearms bending forward) and the left knee
// (the thigh flexing forward to 0.4x the knee angle, so the shin stays clear of
// the body) bend linearly from 0 to end_deg over duration_s; the right leg
// stands still. num_frames = round(duration_s / frame_time_s) + 1.
base::Result<mocap::Motion> MakeBendRamp(const mocap::Skeleton& humanoid, float end_deg = 150.0f,
                                         double duration_s = 2.0, double frame_time_s = 1.0 / 30.0);

// The left upper arm (joint LeftArm) visits five poses, returning to the
// T-pose between them: down at the side (Z -75), raised (Z +60), forward
// (Y -90), back (Y +40) and down in front (Z -60 then Y -50: R = Rz * Ry, the
// arm lowered then swung forward). Each move takes segment_s with a cosine ease
// (zero speed at both ends), so pose k (0..4) is reached exactly at
// (2k + 1) * segment_s and the motion lasts 10 * segment_s. Angles in degrees
// about the joint's own axes, composed in its ZXY order (pose.h).
base::Result<mocap::Motion> MakeShoulderSweep(const mocap::Skeleton& humanoid,
                                              double segment_s = 0.5,
                                              double frame_time_s = 1.0 / 30.0);

// The left leg stretches back (thigh 40 degrees behind, knee straight), returns
// to standing, lifts forward (thigh 80 degrees forward, knee 90 degrees bent)
// and returns; the foot follows the shin (ankle and right leg still). Each move takes
// segment_s with a cosine ease; the stretched-back pose is reached exactly at
// segment_s and the lifted pose at 3 * segment_s; 4 * segment_s in all.
base::Result<mocap::Motion> MakeHipSwing(const mocap::Skeleton& humanoid, double segment_s = 0.5,
                                         double frame_time_s = 1.0 / 30.0);

// Both forearms twist about their bone axis (X) linearly from 0 to end_deg
// (mirrored: the right forearm by -end_deg about +X), arms in T-pose.
base::Result<mocap::Motion> MakeTwistRamp(const mocap::Skeleton& humanoid, float end_deg = 180.0f,
                                          double duration_s = 2.0,
                                          double frame_time_s = 1.0 / 30.0);

// A standing vertical jump: stand, crouch (cosine ease), push with constant
// upward hip acceleration v0^2 / (2 crouch) until the legs are straight at
// take-off speed v0 = sqrt(2 g height), ballistic flight (acceleration -g), a
// landing that absorbs v0 over landing_crouch_cm, recover, stand. The hips'
// vertical acceleration therefore jumps between +push, -g and +landing: the
// spike the elastic layer should answer. Legs follow by two-bone IK with the
// ankles above their rest spot and the feet flat; arms swing forward in the crouch.
struct JumpOptions {
  double frame_time_s = 1.0 / 30.0;
  double height_cm = 30.0;          // hip rise above standing at the apex
  double crouch_cm = 25.0;          // hip drop before take-off (< 84, the leg length)
  double landing_crouch_cm = 20.0;  // hip drop while landing
};
base::Result<mocap::Motion> MakeJumpMotion(const mocap::Skeleton& humanoid,
                                           const JumpOptions& options = {});

// Times (seconds from the first frame) of the jump's phases, for tests.
struct JumpTimeline {
  double crouch_start_s, push_start_s, takeoff_s, touchdown_s, landed_s, recovered_s, end_s;
  double takeoff_speed_cm_per_s;
  double push_acceleration_cm_per_s2;     // upward, constant during the push
  double landing_acceleration_cm_per_s2;  // upward, constant while landing
};
JumpTimeline MakeJumpTimeline(const JumpOptions& options);

// A single chain ("tail") of num_joints joints named Chain0..Chain{N-1}: Chain0
// is the root at (0, 50, 0) with position channels, every next joint is
// segment_length_cm further along -Z; all ZXY rotation channels; an end site.
// kInvalidArgument unless 1 <= num_joints <= kMaxJoints and the length is > 0.
base::Result<mocap::Skeleton> MakeChainSkeleton(int num_joints, float segment_length_cm = 10.0f);

// A simple quadruped standing on y = 0, facing +Z, in cm: Hips (root), Spine,
// Chest, Neck, Head, four legs {Left,Right}{Front,Hind}{UpLeg,Leg,Foot,ToeBase}
// and a two-joint tail (Tail, Tail1); 23 joints, ZXY channels.
mocap::Skeleton MakeQuadrupedSkeleton();

}  // namespace synthetic
