#include "core/logger.h"

#include "core/error.h"

namespace granary {

Logger::Logger(int rank) : rank_(rank) {}
Logger::~Logger() {
  close_log();
}

void Logger::print(const std::string& text) {
  screen_only(text);
  log_only(text);
}

void Logger::screen_only(const std::string& text) {
  if (rank_ == 0 && screen_on_) std::fputs(text.c_str(), stdout);
}

void Logger::log_only(const std::string& text) {
  if (rank_ == 0 && log_) std::fputs(text.c_str(), log_);
}

void Logger::warning(const std::string& text) {
  print("WARNING: " + text + "\n");
}

void Logger::open_log(const std::string& path, bool append) {
  if (rank_ != 0) return;
  std::FILE* f = std::fopen(path.c_str(), append ? "a" : "w");
  if (!f) throw InputError("cannot open log file '" + path + "'; check the directory exists and is writable");
  close_log();
  log_ = f;
}

void Logger::close_log() {
  if (log_) std::fclose(log_);
  log_ = nullptr;
}

void Logger::flush() {
  if (rank_ != 0) return;
  std::fflush(stdout);
  if (log_) std::fflush(log_);
}

}  // namespace granary
