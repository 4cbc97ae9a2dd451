#include "render/video.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <vector>

#include "core/output_file.h"

extern char** environ;

namespace morphoflow {

namespace fs = std::filesystem;

fs::path findOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return {};
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    fs::path p = fs::path(dir) / program;
    std::error_code ec;
    if (fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

namespace {

// ffmpeg's command line: the PNG frames into an H.264 mp4 at `part`.
// libx264 in yuv420p needs even sides: odd frames are padded by one black pixel.
std::vector<std::string> ffmpegArgs(const fs::path& ffmpeg, const VideoRequest& r, const fs::path& part) {
  return {ffmpeg.string(), "-nostdin", "-y", "-hide_banner", "-loglevel", "error",
          "-framerate", std::to_string(r.fps), "-start_number", std::to_string(r.firstFrame),
          "-i", (r.frames / "%06d.png").string(), "-frames:v", std::to_string(r.frameCount),
          "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p",
          "-crf", "18", "-movflags", "+faststart", "-f", "mp4", part.string()};
}

// Starts ffmpeg with its output in `log` and no input: 0, or the errno of a failed start.
int spawnEncoder(const fs::path& ffmpeg, std::vector<std::string> args, const fs::path& log, pid_t* pid) {
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  const int spawned = posix_spawn(pid, ffmpeg.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return spawned;
}

// Waits for the encoder, stopping it (SIGTERM) once `cancelled` says so:
// true when it was stopped, its exit status in *status.
bool awaitEncoder(pid_t pid, const std::function<bool()>& cancelled, int* status) {
  bool stopped = false;
  for (;;) {
    const pid_t w = waitpid(pid, status, WNOHANG);
    if (w == pid || (w < 0 && errno != EINTR)) return stopped;
    if (!stopped && cancelled && cancelled()) {
      kill(pid, SIGTERM);
      stopped = true;
    }
    usleep(20000);
  }
}

}  // namespace

VideoResult encodeVideo(const VideoRequest& r) {
  VideoResult result;
  if (r.frameCount <= 0) {
    result.warning = "no frames were written, so there is no video";
    return result;
  }
  const fs::path ffmpeg = findOnPath("ffmpeg");
  if (ffmpeg.empty()) {
    result.warning = "ffmpeg is not on the PATH, so no video was made (the frames are in " + r.frames.string() +
                     "); install it (apt install ffmpeg) and run again, or set output.video = false";
    return result;
  }
  checkReplaceable(r.file);
  const fs::path part = r.file.string() + ".part";
  checkReplaceable(part);
  result.log = r.file.parent_path() / (r.file.stem().string() + ".ffmpeg.log");
  checkReplaceable(result.log);
  pid_t pid = 0;
  if (const int spawned = spawnEncoder(ffmpeg, ffmpegArgs(ffmpeg, r, part), result.log, &pid); spawned != 0) {
    result.warning = "could not start " + ffmpeg.string() + " (" + std::strerror(spawned) + "), so no video was made";
    return result;
  }
  int status = 0;
  const bool stopped = awaitEncoder(pid, r.cancelled, &status);
  std::error_code ec;
  if (stopped) {
    fs::remove(part, ec);
    result.warning = "the video was not made: the run was interrupted while ffmpeg encoded it";
    return result;
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    fs::remove(part, ec);
    result.warning = "ffmpeg failed (" +
                     (WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                        : std::string("killed by a signal")) +
                     "), so no video was made; its messages are in " + result.log.string();
    return result;
  }
  fs::rename(part, r.file, ec);
  if (ec) {
    result.warning = "could not move the video to " + r.file.string() + ": " + ec.message();
    return result;
  }
  fs::remove(result.log, ec);  // nothing to keep from a clean encode
  result.log.clear();
  result.written = true;
  return result;
}

}  // namespace morphoflow
