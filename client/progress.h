#ifndef CABLESIM_CLIENT_PROGRESS_H_
#define CABLESIM_CLIENT_PROGRESS_H_

// Progress of a long run or sweep on stderr: a bar redrawn in place on a
// terminal, otherwise a plain line at most every 10 s (so logs of CI jobs
// stay short and quick runs print nothing).

#include <chrono>
#include <ostream>
#include <string>

namespace cablesim {

class Progress {
 public:
  // `terminal`: draw a bar (stderr is a terminal).
  Progress(std::ostream* err, bool terminal, std::string label);
  ~Progress();  // Done()
  // `fraction` in [0, 1]; `detail` is appended (e.g. "t = 0.41 s").
  void Update(double fraction, const std::string& detail);
  // Ends the bar's line (terminal only).
  void Done();

  // True when `err` is std::cerr and stderr is a terminal.
  static bool IsTerminal(const std::ostream& err);

 private:
  std::ostream* err_;
  bool terminal_;
  std::string label_;
  std::chrono::steady_clock::time_point start_, last_;
  bool drawn_ = false;
};

}  // namespace cablesim

#endif  // CABLESIM_CLIENT_PROGRESS_H_
