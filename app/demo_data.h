#pragma once
// The built-in demo's inputs, compiled into the binary so `patchskin render`
// works from any directory: samples/data/demo_walk.bvh, a walk cycle the
// project generated (tools/synthetic.h; regenerated and compared by a test).

#include <string_view>

namespace app {

std::string_view DemoBvhText();

}  // namespace app
