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
// PSNR in dB (a log of a computed ratio).
inline constexpr double kPsnrTolDb = 1e-3;

}  // namespace testsupport
