#pragma once
// The elastic part of a rig patch: `patches[i].elastic` (ALGORITHMS.md 6; every
// field is documented in docs/rig-file.md, "Elastic"). Parsed by ParseRigElastic
// (app/internal/rig_elastic_parse.h), hooked into rig_file.cpp's patch parser;
// resolved against a loaded character (driving joint, model units) by
// ResolveRigElastic (app/rig_setup.h).
//
//   "elastic": {"joint": "Hips", "frequency_hz": 3, "damping_ratio": 0.15,
//               "gain": 1, "preroll_s": 1, ...}
//
// An empty object gives the documented defaults (a belly-like jiggle: slowest
// mode at 3 Hz, damping ratio 0.15, 1 s of preroll).

#include <optional>
#include <string>

#include "deform/elastic/mass_spring.h"
#include "base/error.h"

namespace app {

// Parameters of one elastic patch as the rig gives them.
struct RigElastic {
  std::string joint;               // driving joint; empty = the region's joint (a joint
                                   // region) or the joint with the most weight on the
                                   // control points (vertex and screen regions)
  float units_per_metre = 0.0f;    // model units per metre; 0 = from the motion's detected
                                   // units (see UnitsPerMetre)
  double cutoff_hz = 10.0;         // low-pass of the joint paths before differencing; 0 = off
  deform::MassSpringParams params = DefaultParams();  // mass, f0, z0, ratios, h, limits...

  // The library defaults (deform::MassSpringParams) with 1 s of preroll, so the
  // first frame starts settled.
  static deform::MassSpringParams DefaultParams() {
    deform::MassSpringParams p;
    p.preroll_s = 1.0;
    return p;
  }
};

// Model units per metre for a skeleton's detected units: cm 100, m 1, inch
// 39.37; unknown units assume a human-sized character, rest_height / 1.7 m
// (100 when the rest height is unknown too).
float UnitsPerMetre(const std::string& detected_units, float rest_height);

}  // namespace app
