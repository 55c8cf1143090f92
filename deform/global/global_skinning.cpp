#include "deform/global/global_skinning.h"

namespace deform {

const char* GlobalMethodName(GlobalMethod method) {
  switch (method) {
    case GlobalMethod::kSsd: return "ssd";
    case GlobalMethod::kDqs: return "dqs";
    case GlobalMethod::kSwd: return "swd";
  }
  return "?";
}

}  // namespace deform
