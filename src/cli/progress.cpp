#include "progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace rtcl::cli {

Progress::Progress(std::string label, bool quiet) : label_(std::move(label)), enabled_(!quiet && ::isatty(2)) {}

Progress::~Progress() { clear(); }

void Progress::bar(double fraction) {
  if (!enabled_) return;
  int percent = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100.0);
  if (percent == percent_) return;
  percent_ = percent;
  const int width = 40;
  int filled = percent * width / 100;
  std::fprintf(stderr, "\r\033[K%s [%s%s] %3d%%", label_.c_str(), std::string(filled, '#').c_str(),
               std::string(width - filled, ' ').c_str(), percent);
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::status(const std::string& text) {
  if (!enabled_) return;
  std::fprintf(stderr, "\r\033[K%s: %s", label_.c_str(), text.c_str());
  std::fflush(stderr);
  drawn_ = true;
  percent_ = -1;
}

void Progress::clear() {
  if (!drawn_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  drawn_ = false;
  percent_ = -1;
}

}  // namespace rtcl::cli
