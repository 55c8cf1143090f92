#pragma once
// Error reporting shared by every module: a location in a file, an error code,
// a message, and Result<T> which holds either a value or an Error.
//
// Untrusted input (BVH, glTF, rig files, images, command-line arguments) is
// answered with a Result, never an assert or an exception. Messages read like a
// compiler's: "walk.bvh:212:7: error: expected 96 values in frame 118, found 95".

#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace base {

enum class ErrorCode {
  kOk = 0,
  kIo,               // the file could not be opened or read
  kSyntax,           // an unexpected token or missing punctuation
  kBadNumber,        // a token that should be a number is not one
  kNonFinite,        // NaN or infinity where a finite number is required
  kBadChannel,       // unknown, duplicate or too many CHANNELS entries
  kCountMismatch,    // declared and found counts disagree (frames, values, accessors)
  kLimitExceeded,    // a documented limit (joints, depth, frames, bytes) was exceeded
  kUnsupported,      // valid input that this program does not handle
  kInvalidArgument,  // a caller or command-line argument out of range
  kNotFound,         // a named thing (joint, file, field) does not exist
  kInternal,         // a bug in patchskin
};

// Short lowercase name of a code, e.g. "count-mismatch"; used by tests and logs.
std::string_view ErrorCodeName(ErrorCode code);

// A position in an input file. line and column are 1-based; 0 means unknown
// (a whole-file error has neither, a field-path error in JSON uses field_path).
struct FileLoc {
  std::string file;  // as given by the user (not made absolute)
  int line = 0;
  int column = 0;
  std::string field_path;  // e.g. "patches[2].sampling.s" for JSON inputs, else empty

  // "file:line:column", "file:line", "file" or "file: patches[2].s" as available.
  std::string ToString() const;
};

// The whole file, no position in it: errors about a file as a unit (I/O, size).
inline FileLoc InFile(std::string file) { return {std::move(file), 0, 0, {}}; }

struct Error {
  ErrorCode code = ErrorCode::kInternal;
  FileLoc loc;
  std::string message;  // what was expected and what was found, no trailing period

  // "walk.bvh:12:5: error: expected '{' after joint name, found 'OFFSET'".
  std::string ToString() const;
};

// A non-fatal diagnostic, collected beside a result (as tinygltf splits err/warn).
struct Warning {
  FileLoc loc;
  std::string message;
  std::string ToString() const;  // "file:line: warning: message"
};

// Holds either a T or an Error. GCC 12 has no std::expected; this is ours.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT: implicit by design
  Result(Error error) : v_(std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const Error& error() const& { return std::get<1>(v_); }
  Error&& error() && { return std::get<1>(std::move(v_)); }

 private:
  std::variant<T, Error> v_;
};

// Result of an operation that yields nothing but may fail.
class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT: implicit by design
  static Status Ok() { return {}; }

  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const { return error_; }

 private:
  Error error_;
  bool ok_ = true;
};

// Convenience constructor: MakeError(ErrorCode::kSyntax, loc, "expected ...").
Error MakeError(ErrorCode code, FileLoc loc, std::string message);
// The error of a caller's argument out of range (kInvalidArgument), with the
// file position when one applies.
inline Error InvalidArgument(FileLoc loc, std::string message) {
  return MakeError(ErrorCode::kInvalidArgument, std::move(loc), std::move(message));
}
inline Error InvalidArgument(std::string message) {
  return InvalidArgument({}, std::move(message));
}

// Outcome of a job's Validate(): a code plus a static description, so tests can
// tell which check failed (ozz-animation's jobs return bool; we keep the reason).
struct JobStatus {
  enum Code {
    kOk = 0,
    kSizeMismatch,   // two spans that must have the same length do not
    kMissingOutput,  // an optional input is set but its output is not
    kMissingInput,   // a required input is empty
    kOutOfRange,     // a parameter is outside its documented range
  };
  Code code = kOk;
  const char* what = "ok";  // static string, never freed

  bool ok() const { return code == kOk; }
  explicit operator bool() const { return ok(); }
};

inline constexpr JobStatus kJobOk{};

}  // namespace base
