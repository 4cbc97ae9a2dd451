// Encodes a run's PNG frames into an H.264 mp4 with ffmpeg. ffmpeg is found
// on the PATH and started with an argument vector (posix_spawn, never a
// shell); it writes a temporary file that is renamed only when it succeeds,
// so a failed encode leaves no half-written video and never touches frames.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace morphoflow {

struct VideoRequest {
  std::filesystem::path frames;   // DIR/frames with NNNNNN.png
  int firstFrame = 0;             // number of the first frame file
  int frameCount = 0;
  int fps = 30;
  std::filesystem::path file;     // the .mp4 to write
  // Polled while ffmpeg runs: true stops it (SIGTERM) and removes its .part file.
  std::function<bool()> cancelled;
};

struct VideoResult {
  bool written = false;
  std::string warning;            // why not, for the user (empty when written)
  std::filesystem::path log;      // ffmpeg's own messages
};

// Full path of `program` on the PATH, or empty if none is executable.
std::filesystem::path findOnPath(const std::string& program);

VideoResult encodeVideo(const VideoRequest& request);

}  // namespace morphoflow
