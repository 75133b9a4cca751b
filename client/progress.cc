#include "client/progress.h"

#include <unistd.h>

#include <algorithm>
#include <iostream>

#include "absl/strings/str_format.h"

namespace cablesim {

Progress::Progress(std::ostream* err, bool terminal, std::string label)
    : err_(err),
      terminal_(terminal),
      label_(std::move(label)),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

Progress::~Progress() { Done(); }

bool Progress::IsTerminal(const std::ostream& err) {
  return &err == &std::cerr && isatty(STDERR_FILENO) == 1;
}

void Progress::Update(double fraction, const std::string& detail) {
  const auto now = std::chrono::steady_clock::now();
  const double since_last = std::chrono::duration<double>(now - last_).count();
  fraction = std::clamp(fraction, 0.0, 1.0);
  if (terminal_) {
    if (drawn_ && since_last < 0.1 && fraction < 1) return;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    *err_ << "\r" << label_ << " [" << std::string(filled, '#') << std::string(kWidth - filled, ' ')
          << "] " << absl::StrFormat("%3.0f%% ", 100 * fraction) << detail << "\033[K";
    err_->flush();
    drawn_ = true;
  } else {
    if (since_last < 10) return;
    *err_ << label_ << ": " << absl::StrFormat("%.0f%% ", 100 * fraction) << detail << "\n";
    err_->flush();
  }
  last_ = now;
}

void Progress::Done() {
  if (terminal_ && drawn_) {
    *err_ << "\n";
    err_->flush();
  }
  drawn_ = false;
}

}  // namespace cablesim
