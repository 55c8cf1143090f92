// Replays fuzz corpora through a fuzz target's LLVMFuzzerTestOneInput with the
// normal compiler (no libFuzzer): every regular file under each argument (a
// file or a folder, walked recursively) is read and passed in once. A crash,
// sanitizer report or hang fails the ctest that runs it; an input slower than
// kMaxSecondsPerInput is reported and fails the run too, since the fuzzer
// would call it a hang.
//
//   fuzz_replay_bvh tests/data/bvh fuzz/corpus/bvh

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

constexpr double kMaxSecondsPerInput = 10.0;

std::vector<std::filesystem::path> Inputs(const std::filesystem::path& root) {
  std::vector<std::filesystem::path> out;
  std::error_code ec;
  if (std::filesystem::is_regular_file(root, ec)) {
    out.push_back(root);
  } else if (std::filesystem::is_directory(root, ec)) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root, ec)) {
      if (entry.is_regular_file()) out.push_back(entry.path());
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int replayed = 0, slow = 0, missing = 0;
  for (int i = 1; i < argc; ++i) {
    std::vector<std::filesystem::path> files = Inputs(argv[i]);
    if (files.empty()) {
      std::fprintf(stderr, "replay: %s: no input files\n", argv[i]);
      ++missing;
      continue;
    }
    std::sort(files.begin(), files.end());
    for (const std::filesystem::path& file : files) {
      std::ifstream in(file, std::ios::binary);
      const std::vector<char> bytes{std::istreambuf_iterator<char>(in),
                                    std::istreambuf_iterator<char>()};
      const auto start = std::chrono::steady_clock::now();
      LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (seconds > kMaxSecondsPerInput) {
        std::fprintf(stderr, "replay: %s: took %.1f s (limit %.0f s)\n", file.c_str(), seconds,
                     kMaxSecondsPerInput);
        ++slow;
      }
      ++replayed;
    }
  }
  std::printf("replay: %d inputs, %d slow, %d missing folders\n", replayed, slow, missing);
  return slow == 0 && missing == 0 && replayed > 0 ? 0 : 1;
}
