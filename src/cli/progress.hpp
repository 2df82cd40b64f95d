// The progress display of the long subcommands (render, trace, bench): one
// line on stderr, redrawn in place, only when stderr is a terminal and -q is
// not given; cleared before anything else is printed and at the end, so
// that stdout and a redirected stderr carry no progress text.
#pragma once

#include <string>

namespace rtcl::cli {

class Progress {
 public:
  // `label` starts the line ("rendering", "rtcl trace").
  Progress(std::string label, bool quiet);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // "LABEL [#####     ]  42%", redrawn only when the percentage changes.
  void bar(double fraction);
  // "LABEL: TEXT".
  void status(const std::string& text);
  // Erases the line (before other output, and at the end).
  void clear();

 private:
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  int percent_ = -1;
};

}  // namespace rtcl::cli
