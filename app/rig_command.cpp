#include "app/rig_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/auto_rig.h"
#include "app/exit_code.h"
#include "app/rig_writer.h"

namespace app {

int RunRigAuto(const RigCommandOptions& o) {
  base::Result<AutoRig> made = MakeAutoRig(o.capture, o.body, o.up, o.quiet);
  if (!made.ok()) return ReportError(made.error());
  const std::string folder =
      o.out.empty() ? std::string(".") : std::filesystem::path(o.out).parent_path().string();
  base::Result<std::string> text = WriteRigJson(made->rig, folder);
  if (!text.ok()) return ReportInternal(text.error());
  if (!o.quiet) {
    for (const std::string& note : made->notes) {
      std::fprintf(stderr, "%s: note: %s\n", o.capture.c_str(), note.c_str());
    }
    std::fprintf(stderr, "%s: %zu patches\n", o.capture.c_str(), made->rig.patches.size());
  }
  if (o.out.empty()) {
    std::fwrite(text->data(), 1, text->size(), stdout);
    return std::fflush(stdout) == 0 ? 0 : 2;
  }
  // Written beside the target and renamed, so a failed write leaves no partial file.
  const std::string tmp = o.out + ".partial";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f.write(text->data(), static_cast<std::streamsize>(text->size()));
    if (!f.flush()) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      std::fprintf(stderr, "%s: error: cannot write the rig file\n", o.out.c_str());
      return 2;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, o.out, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    std::fprintf(stderr, "%s: error: cannot write the rig file\n", o.out.c_str());
    return 2;
  }
  return 0;
}

}  // namespace app
