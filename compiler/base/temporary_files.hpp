// Where sicm puts files it makes for a moment (the C of a build, plots it
// discards), and how it keeps one from outliving an interrupted build.
#pragma once

#include <string>

namespace sicm {

// $TMPDIR when it names an absolute directory, else /tmp.
std::string temporary_directory();

// While one lives, SIGINT, SIGTERM and SIGHUP remove the file at `path`
// before the process ends as the signal would have ended it (a killed
// `sicm build` used to leave its C behind: 9.8 MB for a 100-body system).
// One at a time; SIGKILL cannot be caught.
class RemovedIfInterrupted {
public:
  explicit RemovedIfInterrupted(const std::string &path);
  ~RemovedIfInterrupted();
  RemovedIfInterrupted(const RemovedIfInterrupted &) = delete;
  RemovedIfInterrupted &operator=(const RemovedIfInterrupted &) = delete;
};

} // namespace sicm
