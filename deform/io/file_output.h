#pragma once
// Atomic file output for the geometry writers: the bytes go to a temporary
// "<dir>/.<name>.tmp-<pid>" first and are renamed into place only once
// complete, so a reader (or a crash) never sees a half-written file. The same
// scheme as render/output/image_io.h, for modules that do not link render.

#include <string>
#include <string_view>

#include "base/error.h"

namespace deform {

// "<dir>/.<name>.tmp-<pid>" next to `final_path`.
std::string TemporaryOutputPath(const std::string& final_path);

// Writes `bytes` to `path` atomically (temporary file, then rename). Creates
// no folders. Errors: kIo naming `path` and the OS's reason; the temporary
// file is removed on failure.
base::Status WriteFileAtomic(const std::string& path, std::string_view bytes);

}  // namespace deform
