// Screen and log-file output. Only rank 0 writes; every rank may call.
#pragma once

#include <cstdio>
#include <string>

namespace granary {

class Logger {
 public:
  explicit Logger(int rank);
  ~Logger();

  /// Write text to the screen and the log file (rank 0 only). No newline is added.
  void print(const std::string& text);
  /// Screen only / log file only.
  void screen_only(const std::string& text);
  void log_only(const std::string& text);
  /// "WARNING: ..." on screen and log.
  void warning(const std::string& text);

  /// Open a log file (closing any current one). Throws InputError if it cannot be opened.
  void open_log(const std::string& path, bool append);
  void close_log();
  /// `-screen none`.
  void set_screen(bool on) { screen_on_ = on; }
  bool screen_on() const { return screen_on_; }
  void flush();
  int rank() const { return rank_; }

 private:
  int rank_;
  bool screen_on_ = true;
  std::FILE* log_ = nullptr;
};

}  // namespace granary
