#include "core/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

namespace granary {

namespace {

std::string failure(const std::string& path, const std::string& reason) {
  return "cannot write '" + path + "': " + reason;
}

/// The temporary file being written: created exclusively, removed unless renamed.
class TempFile {
 public:
  explicit TempFile(const std::string& path) : path_(path) {
    static std::atomic<unsigned> counter{0};
    const std::string prefix = temp_prefix(path);
    for (int attempt = 0; attempt < 1000; ++attempt) {
      name_ = prefix + std::to_string(static_cast<long>(::getpid())) + "-" + std::to_string(counter++);
      fd_ = ::open(name_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd_ >= 0 || errno != EEXIST) break;
    }
    if (fd_ < 0) {
      error_ = failure(path, std::strerror(errno));
      name_.clear();
      return;
    }
    struct stat st {};
    if (::fstat(fd_, &st) == 0) {
      dev_ = st.st_dev;
      ino_ = st.st_ino;
    }
  }
  ~TempFile() { discard(); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  const std::string& error() const { return error_; }
  const std::string& name() const { return name_; }

  /// The stream on the descriptor (owned from then on by the stream).
  std::FILE* stream() {
    if (!stream_ && fd_ >= 0) {
      stream_ = ::fdopen(fd_, "w");
      if (stream_) fd_ = -1;
    }
    return stream_;
  }

  /// Close the file; "" or why it failed.
  std::string close() {
    int failed = 0, err = 0;
    if (stream_) {
      failed = std::ferror(stream_) != 0;
      err = errno;
      if (std::fclose(stream_) != 0 && !failed) {
        failed = 1;
        err = errno;
      }
      stream_ = nullptr;
    }
    if (fd_ >= 0) {
      if (::close(fd_) != 0) {
        failed = 1;
        err = errno;
      }
      fd_ = -1;
    }
    return failed ? failure(path_, err ? std::strerror(err) : "write error") : "";
  }

  /// Rename over the final name; "" or why not.
  std::string commit() {
    if (std::string e = close(); !e.empty()) return e;
    if (std::rename(name_.c_str(), path_.c_str()) != 0) {
      return failure(path_, "cannot rename '" + name_ + "' to it: " + std::strerror(errno));
    }
    name_.clear();
    return "";
  }

  /// Remove the temporary file, but only the regular file created here.
  void discard() {
    close();
    if (name_.empty()) return;
    struct stat st {};
    if (::lstat(name_.c_str(), &st) == 0 && S_ISREG(st.st_mode) && st.st_dev == dev_ && st.st_ino == ino_) {
      ::unlink(name_.c_str());
    }
    name_.clear();
  }

 private:
  std::string path_, name_, error_;
  int fd_ = -1;
  std::FILE* stream_ = nullptr;
  dev_t dev_ = 0;
  ino_t ino_ = 0;
};

}  // namespace

std::string temp_prefix(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  return dir + "." + base + ".tmp-";
}

std::string replace_file(const std::string& path, const std::function<void(std::FILE*)>& write) {
  if (path.empty() || path.back() == '/') return failure(path, "the file name is empty");
  TempFile temp(path);
  if (!temp.error().empty()) return temp.error();
  std::FILE* f = temp.stream();
  if (!f) return failure(path, std::strerror(errno));
  write(f);
  return temp.commit();
}

std::string replace_file_by_name(const std::string& path,
                                 const std::function<std::string(const std::string& temp)>& write) {
  if (path.empty() || path.back() == '/') return failure(path, "the file name is empty");
  TempFile temp(path);
  if (!temp.error().empty()) return temp.error();
  if (std::string e = temp.close(); !e.empty()) return e;
  if (std::string e = write(temp.name()); !e.empty()) return e;
  return temp.commit();
}

std::string replace_file(const std::string& path, const std::string& text) {
  return replace_file(path, [&](std::FILE* f) { std::fwrite(text.data(), 1, text.size(), f); });
}

}  // namespace granary
