#pragma once
// AsyncImageWriter: writes frames on worker threads while the caller renders the
// next one. Encoding a 1280x720 PNG costs far more than drawing it, so the render
// loop hands each finished frame over and goes on.
//
//   render::AsyncImageWriter writer({.num_workers = 2, .max_in_flight = 4});
//   for (int f = first; f <= last; ++f) {
//     render::Image frame = Render(f);
//     if (Status s = writer.Submit(std::move(frame), Path(f), options); !s) return s;
//   }
//   if (Status s = writer.Finish(); !s) return s;
//
// Memory is bounded: at most max_in_flight frames are queued or being encoded;
// Submit blocks until one finishes when that many are. Each frame is encoded by
// WriteImage on its own, so the bytes of every file are the same whatever the
// number of workers or the order they finish in. Errors: the first failing frame's
// error is returned by the next Submit (which then refuses further frames) and by
// Finish; frames already queued are still written.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "render/image.h"
#include "render/output/image_io.h"

namespace render {

struct AsyncWriterOptions {
  int num_workers = 2;    // encoder threads, >= 1 (smaller values are raised to 1)
  int max_in_flight = 4;  // frames queued or encoding at once, >= num_workers (raised to it)
};

class AsyncImageWriter {
 public:
  explicit AsyncImageWriter(AsyncWriterOptions options = {});
  ~AsyncImageWriter();  // Finish(); an error not yet returned is dropped
  AsyncImageWriter(const AsyncImageWriter&) = delete;
  AsyncImageWriter& operator=(const AsyncImageWriter&) = delete;

  // Queues `image` to be written to `path` (see WriteImage). Blocks while
  // max_in_flight frames are pending. Returns the first error of any earlier frame,
  // after which nothing more is queued; also an error after Finish.
  [[nodiscard]] Status Submit(Image image, std::string path, WriteOptions options = {});
  // The same for a frame already sRGB-encoded (8-bit formats only; see
  // WriteImage), shared with its other consumers (the video, the sheet).
  [[nodiscard]] Status Submit(std::shared_ptr<const Srgb8Image> image, std::string path,
                              WriteOptions options = {});

  // Waits for every queued frame, stops the workers and returns the first error
  // (or Ok). Calling it again returns the same status.
  [[nodiscard]] Status Finish();

  // An image whose frame has been written, with its buffers' capacity kept
  // (contents unspecified), or an empty Image when none is free yet. Rendering
  // the next frame into it saves allocating and first-touching a frame-sized
  // buffer per frame. At most max_in_flight written images are kept for this.
  Image TakeSpareImage();

  // Frames written successfully so far (thread-safe).
  std::int64_t frames_written() const;
  // Most frames that were queued or encoding at once (<= max_in_flight; thread-safe).
  int peak_in_flight() const;

 private:
  struct Job {
    Image image;                                // written when `encoded` is null
    std::shared_ptr<const Srgb8Image> encoded;  // or these bytes
    std::string path;
    WriteOptions options;
    std::int64_t sequence = 0;  // submission order
  };
  Status Queue(Job job);  // Submit's common part
  void WorkerLoop();

  AsyncWriterOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable work_ready_;  // a job was queued or stopping_ was set
  std::condition_variable slot_free_;   // in_flight_ dropped
  std::deque<Job> queue_;
  std::vector<Image> spares_;           // written frames' buffers, for TakeSpareImage
  int in_flight_ = 0;                   // queued + encoding
  int peak_in_flight_ = 0;
  bool stopping_ = false;
  bool finished_ = false;
  std::optional<base::Error> first_error_;
  std::int64_t first_error_sequence_ = 0;  // the earliest failing submission reported
  std::int64_t next_sequence_ = 0;
  std::int64_t frames_written_ = 0;
  std::vector<std::thread> workers_;
};

}  // namespace render
