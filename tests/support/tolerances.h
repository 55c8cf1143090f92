#pragma once
// Named tolerances for tests: never a bare literal in an assertion.

namespace testsupport {

// Float round-off of a few operations on values of order 1..100.
inline constexpr float kFloatTol = 1e-5f;
// Positions after a chain of float transforms in file units (cm-scale skeletons).
inline constexpr float kPositionTol = 1e-3f;
// Angles compared in degrees after Euler/quaternion round trips.
inline constexpr float kAngleTolDeg = 1e-3f;
// Double-precision solves (fits, RBF, projections).
inline constexpr double kDoubleTol = 1e-9;
// Example shapes at the rest pose, relative to the patch diagonal: dS(rest) = 0
// holds in exact arithmetic; the float RBF sum leaves round-off of its
// weights (~1e-7 x the displacements) times a few control points.
inline constexpr double kRestRoundoffRel = 1e-5;

// Euler angles (degrees) extracted from a float quaternion and compared with the
// angles that built it: float quaternion round-off (~6e-8) amplified by the
// atan2/asin of the extraction, away from gimbal lock.
inline constexpr float kEulerRoundTripTolDeg = 2e-3f;
// Angle between two rotations (radians) after a float round trip.
inline constexpr float kRotationTolRad = 1e-5f;
// Within 0.1 degree of gimbal lock asin loses half the digits: rotations rebuilt
// from extracted angles agree to ~sqrt(float eps).
inline constexpr float kGimbalRotationTolRad = 2e-3f;
inline constexpr float kGimbalAngleTolDeg = 0.1f;
// Channel values (degrees or file units of order 100) after a resampling round
// trip: sampled exactly at the original frames, then re-extracted from floats.
inline constexpr float kResampleChannelTol = 5e-3f;
// Largest change of an Euler channel between neighbouring resampled frames of a
// smooth motion that moves < 40 degrees per frame: catches 360-degree jumps.
inline constexpr float kMaxAngleStepDeg = 45.0f;

// Finite-difference kinematics. Tests compute their tolerance from the scheme's
// truncation bound (h^2/6 |x'''| for central first derivatives, h^2/12 |x''''|
// for second ones, h |x'''| for the first-order end formulas) plus float
// round-off of the model matrices, times this safety factor.
inline constexpr double kFdSafety = 2.0;
// Relative float round-off of a model-matrix position after a short joint chain.
inline constexpr double kMatrixRoundoff = 4.0 * 1.1920929e-7;
// Halving the step of a second-order scheme divides its error by 4; accept >3.
inline constexpr double kSecondOrderMinRatio = 3.0;
// Relative float error of rotating a vector into a joint's frame.
inline constexpr float kLocalFrameRelTol = 1e-5f;
// The 10 Hz Gaussian low-pass passes 0.4% of a 40 Hz component (sampled kernel:
// a little more); accept up to 2% of the unfiltered error.
inline constexpr double kLowPassResidual = 0.02;
// Angular velocity (rad/s) after smoothing a fixed-axis quadratic rotation: the
// normalized quaternion mean differs from the angle mean at O(spread^3).
inline constexpr double kLowPassAngularVelTol = 1e-3;

// Synthetic motions. A procedural walk keeps the stance foot within this of the
// ground (the hips bob is solved exactly; float positions round at ~1e-5 cm, so
// this is slack for the foot-flat approximation only).
inline constexpr float kGroundContactTolCm = 0.05f;
// A planted foot moves less than this between frames (float positions of
// order 300 cm round at ~4e-5 cm).
inline constexpr float kFootSlideTolCm = 0.01f;
// Joint bend angles measured from float model positions (acos near 0 and 180
// degrees loses precision: sqrt(float eps) ~ 3e-4 rad ~ 0.02 degrees).
inline constexpr float kBendMeasureTolDeg = 0.05f;
// Hips vertical acceleration of the jump at 120 fps: the motion is piecewise
// quadratic, so central differences are exact up to float round-off of positions
// near 100 cm (4 * 1e-5 cm / h^2 = 0.6 cm/s^2).
inline constexpr float kJumpAccelTolCmPerS2 = 2.0f;
// Apex of the hips sampled at 120 fps: the nearest frame is at most h/2 from the
// peak, so at most g (h/2)^2 / 2 = 0.009 cm below it, plus round-off.
inline constexpr float kJumpApexTolCm = 0.02f;


// Inverse bind matrix x rest-pose joint matrix vs identity: the files store
// both in float after an exporter's own float products.
inline constexpr float kBindIdentityTol = 1e-4f;
// Skinned glTF vertices (metres) from two float evaluation paths compared
// with a double reference: float round-off over a ~20-joint chain.
inline constexpr double kSkinnedVertexTol = 1e-4;


// Skinning with a rigid palette: positions of order 1..10 after one blended
// 3x4 transform (edge lengths, rigid-map comparisons).
inline constexpr float kSkinningTol = 1e-4f;
// Smallest triangle area accepted in a generated mesh, as a fraction of the
// body size squared (a 24-vertex ring at 0.004 S radius makes ~1e-6 S^2 cells).
inline constexpr float kMinTriangleAreaFraction = 1e-9f;
// How far the mannequin's height along the up axis may differ from the
// skeleton's joint-and-end-site height (head and foot soles add thickness).
inline constexpr float kMannequinHeightTolFraction = 0.25f;
// Cross-section area ratios of a 64-gon ring (polygon vs analytic shrink).
inline constexpr float kPolygonAreaRatioTol = 0.01f;
// Rendered colour against an analytic value where only float round-off and
// 1/256-pixel vertex snapping differ (perspective-correct interpolation).
inline constexpr float kRenderTol = 2e-3f;
// Relative view-depth error of a vertex the rasterizer created on a clip plane
// (float interpolation in clip space, then 1 / (1/w)).
inline constexpr float kClipDepthRelTol = 1e-5f;
// Shading of a tessellated sphere against the analytic sphere's N.L (the
// interpolated normal of a 64x128 UV sphere is off by well under 1 degree).
inline constexpr float kTessellatedShadingTol = 5e-3f;
// GroundShader (float ray through the sample, hoisted reciprocals, polynomial
// exp) against GroundAlbedo * ContactShadowFactor at a double-precision ray
// hit: on a grid line's soft edge (0.04 spacings wide) a 1e-6 relative
// position error moves the weight by ~1e-3 of the line contrast (0.2); a
// quarter of one 8-bit step.
inline constexpr float kGroundShaderTol = 1e-3f;
// A smoothly varying shaded value read at the pixel containing a projected
// point rather than at the point itself.
inline constexpr float kPixelFootprintTol = 2e-2f;
// Half floats (EXR) keep an 11-bit significand: relative error <= 2^-11.
inline constexpr float kHalfRelTol = 1.0f / 2048.0f;
// Smallest absolute step kept for tiny values after a half round trip.
inline constexpr float kHalfAbsTol = 1e-7f;
// One code of a 16-bit integer sample, in [0, 1] units.
inline constexpr float kUint16Step = 1.0f / 65535.0f;
// JPEG at quality 95 on a flat colour: within 3 of 255 codes (sRGB units).
inline constexpr float kJpegFlatTol = 3.0f / 255.0f;
// Lossy video codecs on flat grey frames: mean within 6 of 255 codes.
inline constexpr double kVideoFlatTol8 = 6.0;
// Lossy video codecs on saturated primaries (YUV 4:2:0, studio range), away
// from the colour borders: within 24 of 255 codes (a swapped channel is 255 off).
inline constexpr double kVideoColourTol8 = 24.0;
// PSNR in dB (a log of a computed ratio).
inline constexpr double kPsnrTolDb = 1e-3;
// SWD: bind-pose rebuild error relative to the mesh size (ALGORITHMS.md 2.3 asks 1e-5).
inline constexpr float kSwdRebuildRelTol = 1e-5f;
// Area ratios of vertex rings (SWD fixtures) compared with closed forms (float positions, double areas).
inline constexpr double kAreaRatioTol = 1e-4;
// Sweep centre-curve continuity: a step of kCurveStep in u moves c by about speed * step.
inline constexpr double kCurveStep = 1e-7;
inline constexpr double kCurveDirectionTol = 1e-5;  // radians between tangent directions
// B-spline identities in double (partition of unity, Cox-de Boor agreement).
inline constexpr double kSplineTol = 1e-12;
// Central finite differences of B-spline derivatives (step 1e-6 in parameter).
inline constexpr double kFiniteDiffTol = 1e-5;
// Knot insertion and refinement keep the surface (ALGORITHMS.md 7).
inline constexpr double kKnotInsertionTol = 1e-6;
// Rest rebuild of bound vertices, relative to the patch size (ALGORITHMS.md 3.5).
inline constexpr double kRebuildRelTol = 1e-4;
// Projection recovering known (u,v,d) (Newton stops at 1e-7 x diagonal).
inline constexpr double kProjectionTol = 1e-6;

// `inspect` world positions (float chains, printed with 6+ digits) against a
// double-precision reference, relative to the figure's largest coordinate.
inline constexpr double kInspectRelTol = 2e-5;
// Pose-space RBF evaluated in float against the examples it was fitted to
// (weights solved in double, displacements of order 1 model unit).
inline constexpr float kRbfExactTol = 1e-4f;
// Direct manipulation: a solved constraint lands on its target (double, relative to the patch size).
inline constexpr double kConstraintRelTol = 1e-9;
// A vertex edit measured on the float rebuild (PatchRebuildJob), relative to the patch size.
inline constexpr double kVertexEditRelTol = 1e-5;
// Rotations compared component-wise (polar factor, blended frames; float quaternions).
inline constexpr float kRotationTol = 1e-5f;

}  // namespace testsupport

namespace testsupport {

// A morph-target frame read back: base + (frame - base) in float, for values of
// order 1 (round-off of one subtraction and one addition, a few ulps).
inline constexpr float kMorphRoundTripTol = 1e-6f;

// Streaming exports: the peak memory growth from 100 to 1000 frames, as a
// share of what holding the extra 900 frames' vertex data would take. What
// legitimately grows is per-frame bookkeeping (the frame plan; for .glb about
// 1 KB of accessor/view descriptions and JSON per frame), a few percent of it.
inline constexpr double kStreamingGrowthShare = 0.25;
// glb size estimates (JSON bytes per frame approximated) vs the written file.
inline constexpr double kGlbSizeEstimateRelTol = 0.15;
// Two glb layouts whose files differ by less than this are a tie for the
// automatic choice (it decides on estimates).
inline constexpr double kGlbLayoutTieRelTol = 0.02;
// Candy-wrapper figure under a 180 degree twist of the hand on the mannequin: SSD's
// blend collapses the forearm rings to well under this area ratio...
inline constexpr double kCandyWrapperCollapsedMax = 0.5;
// ...while DQS and SWD keep at least this much of them.
inline constexpr double kCandyWrapperKeptMin = 0.8;

// SWD on a mannequin: largest growth of any edge, as a fraction of the body size. A tear
// (a tube part following the wrong bone) opens gaps of a limb radius (5-10%); the rest-bent
// ankle's inner side, bound ambiguously, creases by up to about 3%.
inline constexpr float kSwdMaxEdgeGrowthFraction = 0.04f;
// The same on the shared captures (CMU, LAFAN, Bandai Namco, bvh_python) at their first,
// middle and last frame: bodies bound in odd rest poses (a raised leg beside the head)
// once tore by up to 0.87 S; the ambiguous inner ankle and the back crease by under 2%.
inline constexpr float kSwdCaptureMaxEdgeGrowthFraction = 0.03f;
// SWD with patches and no displacement: largest distance of a rebuilt region vertex from
// the SWD-only result, as a share of the patch's control-grid diagonal. The carried
// control polygon only approximates the body, so the rebuilt surface differs from it by
// the fit's own error bent along (a few percent); a control point bound to the wrong
// sweep moves by a limb's length instead.
inline constexpr double kSwdPatchFollowRelTol = 0.1;

}  // namespace testsupport

namespace testsupport {

// Mass-spring network (ALGORITHMS.md 6). Period of the slowest mode measured by
// zero crossings of a float RK4 run at h = 1/240 s (RK4 phase error ~(wh)^4/120).
inline constexpr double kModePeriodRelTol = 1e-3;
// Damping ratio from the log decrement of parabola-interpolated peaks.
inline constexpr double kDampingRatioTol = 5e-3;
// Energy of a damped linear network may not grow between steps beyond float round-off.
inline constexpr double kEnergyMonotoneRelTol = 1e-5;
// Energy left 4 s after the motion stops, relative to the energy at the stop.
inline constexpr double kRestEnergyFraction = 1e-6;
// Displacement (cm) counted as "back at rest".
inline constexpr float kRestDisplacementCm = 1e-3f;
// Settled displacement under constant acceleration vs the static solution.
inline constexpr double kStaticResponseRelTol = 1e-3;
// Modal and point-space integration of the same linear system (float round-off
// over a few hundred steps), relative to the largest displacement.
inline constexpr double kSolverAgreementRelTol = 1e-4;
// RK4: halving h divides the global error by 16; accept more than 12.
inline constexpr double kFourthOrderMinRatio = 12.0;
inline constexpr double kFourthOrderMaxRatio = 20.0;

}  // namespace testsupport

namespace testsupport {

// The synthetic jump resampled at 30, 60 and 120 fps (10 Hz low-pass) drives the
// same patch: the largest difference of the centre point's displacement curve
// from the 120 fps one, relative to its peak (measured 6.8% and 2.0%). The
// forcing differs only by each rate's finite-difference kinematics: the jump's
// acceleration steps are smeared over a frame, 33 ms at 30 fps.
inline constexpr double kFrameRateAgreement30 = 0.08;
inline constexpr double kFrameRateAgreement60 = 0.03;
// First frame after a 3 s preroll vs the settled sag under a constant load.
inline constexpr double kPrerollSettledRel = 0.01;

}  // namespace testsupport

namespace testsupport {

// Elastic layer in the pipeline (tests/app/elastic_pipeline_test.cpp).
// The sample belly's peak displacement after the jump's landing must be at
// least this (cm): visible at a normal framing (the landing pushes ~15 m/s^2,
// ~2.3 cm static at 4 Hz).
inline constexpr float kElasticVisiblePeakCm = 1.0f;
// After the body stands still for 1.5 s, the jiggle must have decayed below this
// fraction of the landing peak (damping ratio 0.15 at 4 Hz: 5 % after ~0.8 s).
inline constexpr float kElasticSettledFraction = 0.05f;

}  // namespace testsupport

namespace testsupport {

// The polar factor of a blend of rotations by Newton's iteration against the
// SVD's, in double, per matrix entry (the stopping rule leaves ~1e-13).
inline constexpr double kPolarFactorTol = 1e-10;

}  // namespace testsupport
