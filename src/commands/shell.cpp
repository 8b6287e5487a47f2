// The shell command: cd, mkdir, mv, rm, rmdir, putenv, or any other command
// through the C library's system() (doc/commands/shell.md).
#include <mpi.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <sys/wait.h>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"

namespace granary {

namespace {

namespace fs = std::filesystem;

// Rank 0's message, or "" when it succeeded, on every rank.
std::string on_rank0(Engine& e, const std::function<std::string()>& act) {
  std::string msg;
  if (e.rank == 0) msg = act();
  int n = static_cast<int>(msg.size());
  MPI_Bcast(&n, 1, MPI_INT, 0, e.world);
  msg.resize(static_cast<std::size_t>(n));
  MPI_Bcast(msg.data(), n, MPI_CHAR, 0, e.world);
  return msg;
}

void cmd_shell(Engine& e, const Args& a) {
  if (a.empty()) {
    throw InputError(
        "shell needs a command: cd DIR, mkdir DIR..., mv OLD NEW, rm FILE..., rmdir DIR..., putenv "
        "VAR=VALUE..., "
        "or any program with its arguments");
  }
  const std::string& cmd = a[0];
  const Args args(a.begin() + 1, a.end());
  std::error_code ec;
  if (cmd == "cd") {
    if (args.size() != 1) throw InputError("shell cd needs one directory");
    // every rank changes directory; all must succeed, or none goes on
    int ok = ::chdir(args[0].c_str()) == 0 ? 1 : 0, all = 0;
    MPI_Allreduce(&ok, &all, 1, MPI_INT, MPI_MIN, e.world);
    if (!all) {
      throw InputError("shell cd: cannot change to directory '" + args[0] +
                       "' (on at least one rank); check that it exists");
    }
    return;
  }
  if (cmd == "putenv") {
    if (args.empty()) throw InputError("shell putenv needs VAR=VALUE definitions");
    for (const auto& def : args) {
      const auto eq = def.find('=');
      if (eq == std::string::npos || eq == 0)
        throw InputError("shell putenv: '" + def + "' is not VAR=VALUE");
    }
    for (const auto& def : args) {
      const auto eq = def.find('=');
      ::setenv(def.substr(0, eq).c_str(), def.substr(eq + 1).c_str(), 1);
    }
    return;
  }
  std::string problem;
  if (cmd == "mkdir") {
    if (args.empty()) throw InputError("shell mkdir needs at least one directory");
    problem = on_rank0(e, [&]() -> std::string {
      for (const auto& d : args) {
        fs::create_directories(d, ec);
        if (!fs::is_directory(d)) return "shell mkdir: cannot create directory '" + d + "'";
      }
      return "";
    });
  } else if (cmd == "mv") {
    if (args.size() != 2) throw InputError("shell mv needs an old and a new name");
    problem = on_rank0(e, [&]() -> std::string {
      fs::path to = args[1];
      if (fs::is_directory(to)) to /= fs::path(args[0]).filename();
      fs::rename(args[0], to, ec);
      return ec ? "shell mv: cannot move '" + args[0] + "' to '" + to.string() + "': " + ec.message() : "";
    });
  } else if (cmd == "rm") {
    if (args.empty()) throw InputError("shell rm needs at least one file");
    // a file that is not there: a warning (scripts clean up before they write)
    const std::string missing = on_rank0(e, [&]() -> std::string {
      std::string gone;
      for (const auto& f : args) {
        if (fs::is_directory(f)) return "is a directory:" + f;
        if (!fs::remove(f, ec)) gone += " '" + f + "'";
      }
      return gone;
    });
    if (missing.rfind("is a directory:", 0) == 0) {
      throw InputError("shell rm: '" + missing.substr(15) + "' is a directory; remove it with shell rmdir");
    }
    if (!missing.empty()) e.logger->warning("shell rm: no file" + missing + " to remove");
    return;
  } else if (cmd == "rmdir") {
    if (args.empty()) throw InputError("shell rmdir needs at least one directory");
    problem = on_rank0(e, [&]() -> std::string {
      for (const auto& d : args) {
        if (!fs::is_directory(d)) return "shell rmdir: '" + d + "' is not a directory";
        if (!fs::is_empty(d, ec)) return "shell rmdir: directory '" + d + "' is not empty";
        fs::remove(d, ec);
        if (ec) return "shell rmdir: cannot remove '" + d + "': " + ec.message();
      }
      return "";
    });
  } else {
    // any other program, on rank 0 through the shell; its exit status is reported
    std::string line = cmd;
    for (const auto& w : args)
      line += " " + w;
    const std::string status = on_rank0(e, [&]() -> std::string {
      std::fflush(nullptr);
      const int rc = std::system(line.c_str());
      if (rc == -1) return "could not be started";
      if (WIFEXITED(rc) && WEXITSTATUS(rc) == 0) return "";
      if (WIFEXITED(rc)) return "exited with status " + std::to_string(WEXITSTATUS(rc));
      return "ended by a signal";
    });
    if (!status.empty()) e.logger->warning("shell: '" + line + "' " + status);
    return;
  }
  if (!problem.empty()) throw InputError(problem);
}

}  // namespace

GRANARY_COMMAND("shell", cmd_shell);

}  // namespace granary
