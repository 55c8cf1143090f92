#include "render/output/async_writer.h"

#include <algorithm>
#include <utility>

namespace render {

AsyncImageWriter::AsyncImageWriter(AsyncWriterOptions options) : options_(options) {
  options_.num_workers = std::max(options_.num_workers, 1);
  options_.max_in_flight = std::max(options_.max_in_flight, options_.num_workers);
  workers_.reserve(static_cast<std::size_t>(options_.num_workers));
  for (int i = 0; i < options_.num_workers; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

AsyncImageWriter::~AsyncImageWriter() { (void)Finish(); }

Status AsyncImageWriter::Submit(Image image, std::string path, WriteOptions options) {
  Job job;
  job.image = std::move(image);
  job.path = std::move(path);
  job.options = std::move(options);
  return Queue(std::move(job));
}

Status AsyncImageWriter::Submit(std::shared_ptr<const Srgb8Image> image, std::string path,
                                WriteOptions options) {
  if (image == nullptr) return base::InvalidArgument(base::InFile(path), "no frame to write");
  Job job;
  job.encoded = std::move(image);
  job.path = std::move(path);
  job.options = std::move(options);
  return Queue(std::move(job));
}

Status AsyncImageWriter::Queue(Job job) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (finished_) {
    return base::InvalidArgument(base::InFile(job.path),
                                 "frame submitted after the writer finished");
  }
  slot_free_.wait(lock, [&] { return in_flight_ < options_.max_in_flight || first_error_; });
  if (first_error_) return *first_error_;
  job.sequence = next_sequence_++;
  queue_.push_back(std::move(job));
  ++in_flight_;
  peak_in_flight_ = std::max(peak_in_flight_, in_flight_);
  work_ready_.notify_one();
  return Status::Ok();
}

Status AsyncImageWriter::Finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!finished_) {
      finished_ = true;
      stopping_ = true;
      work_ready_.notify_all();
    }
  }
  for (std::thread& t : workers_) {
    if (t.joinable()) t.join();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (first_error_) return *first_error_;
  return Status::Ok();
}

Image AsyncImageWriter::TakeSpareImage() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (spares_.empty()) return Image();
  Image image = std::move(spares_.back());
  spares_.pop_back();
  return image;
}

std::int64_t AsyncImageWriter::frames_written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_written_;
}

int AsyncImageWriter::peak_in_flight() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return peak_in_flight_;
}

void AsyncImageWriter::WorkerLoop() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_ready_.wait(lock, [&] { return !queue_.empty() || stopping_; });
      if (queue_.empty()) return;  // stopping and drained
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    const Status status = job.encoded ? WriteImage(*job.encoded, job.path, job.options)
                                      : WriteImage(job.image, job.path, job.options);
    std::lock_guard<std::mutex> lock(mutex_);
    // Keep the buffers for TakeSpareImage, or release them before signalling a free slot.
    if (!job.encoded && static_cast<int>(spares_.size()) < options_.max_in_flight && !stopping_) {
      spares_.push_back(std::move(job.image));
    }
    job.image = Image();
    job.encoded.reset();
    if (status) {
      ++frames_written_;
    } else if (!first_error_ || job.sequence < first_error_sequence_) {
      first_error_ = status.error();
      first_error_sequence_ = job.sequence;
    }
    --in_flight_;
    slot_free_.notify_all();
  }
}

}  // namespace render
