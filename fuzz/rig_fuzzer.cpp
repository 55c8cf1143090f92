// libFuzzer target: the rig-file reader (app::ParseRig) on arbitrary bytes.
// ParseRig reads no other file (it only resolves the character, motion and
// output paths against the rig's folder), and the rig is named inside a folder
// that does not exist, so the fuzzer never touches the disk. Whatever the
// bytes, the reader must return a Result: no exception escaping, no crash, no
// deep recursion, no allocation beyond what the text's size allows.

#include <cstddef>
#include <cstdint>
#include <string>

#include "app/rig_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  base::Result<app::Rig> rig = app::ParseRig(text, "/nonexistent-patchskin-fuzz/rig.json");
  if (!rig.ok()) {
    (void)rig.error().ToString();
    return 0;
  }
  // What a parse accepts must hold the documented ranges (the renderer relies on them).
  for (const app::RigPatch& p : rig->patches) {
    if (p.grid.x < 4 || p.grid.y < 4 || p.grid.x > 64 || p.grid.y > 64 || p.sampling.x < p.grid.x ||
        p.sampling.y < p.grid.y || p.sampling.x > 256 || p.sampling.y > 256) {
      __builtin_trap();
    }
  }
  if (rig->render.size.x < 16 || rig->render.size.y < 16 || rig->render.size.x > 16384 ||
      rig->render.size.y > 16384) {
    __builtin_trap();
  }
  return 0;
}
