#include "base/error.h"

namespace base {

std::string_view ErrorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk: return "ok";
    case ErrorCode::kIo: return "io";
    case ErrorCode::kSyntax: return "syntax";
    case ErrorCode::kBadNumber: return "bad-number";
    case ErrorCode::kNonFinite: return "non-finite";
    case ErrorCode::kBadChannel: return "bad-channel";
    case ErrorCode::kCountMismatch: return "count-mismatch";
    case ErrorCode::kLimitExceeded: return "limit-exceeded";
    case ErrorCode::kUnsupported: return "unsupported";
    case ErrorCode::kInvalidArgument: return "invalid-argument";
    case ErrorCode::kNotFound: return "not-found";
    case ErrorCode::kInternal: return "internal";
  }
  return "unknown";
}

std::string FileLoc::ToString() const {
  std::string out = file.empty() ? std::string("<input>") : file;
  if (line > 0) {
    out += ':' + std::to_string(line);
    if (column > 0) out += ':' + std::to_string(column);
  }
  if (!field_path.empty()) out += ": " + field_path;
  return out;
}

std::string Error::ToString() const { return loc.ToString() + ": error: " + message; }

std::string Warning::ToString() const { return loc.ToString() + ": warning: " + message; }

Error MakeError(ErrorCode code, FileLoc loc, std::string message) {
  return Error{code, std::move(loc), std::move(message)};
}

}  // namespace base
