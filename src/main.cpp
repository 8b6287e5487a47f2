// granary: run a LAMMPS/LIGGGHTS-style input script (see doc/command_line.md).
#include <mpi.h>

#include <cctype>
#include <cstdio>
#include <exception>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/stop_signal.h"
#include "core/style_list.h"
#include "core/variable.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#ifndef GRANARY_VERSION
#define GRANARY_VERSION "0.1.0"
#endif

namespace {

const char* const kUsage =
    "Usage: granary [options]\n"
    "  -in FILE, -i FILE             read the input script from FILE (default: standard input)\n"
    "  -var NAME V1 [V2 ...], -v     define an index variable; the script's own\n"
    "                                'variable NAME ...' then leaves it alone\n"
    "  -log FILE|none, -l            log file (default log.granary; none: no log file)\n"
    "  -echo screen|log|both|none, -e  echo input commands (default: log)\n"
    "  -screen none, -sc             write nothing to the screen\n"
    "  -list-styles                  print the commands and styles this build knows\n"
    "                                (one 'KIND NAME' per line) and exit\n"
    "  -help, -h                     print this help and exit\n";

struct Options {
  std::string in;
  bool have_in = false;
  std::vector<std::pair<std::string, std::vector<std::string>>> vars;
  std::string log = "log.granary";
  std::string echo;
  bool screen = true;
  bool help = false;
  bool list_styles = false;
};

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A word that starts an option (so "-1.5" can still be a -var value).
bool is_option(const std::string& w) {
  return w.size() >= 2 && w[0] == '-' && std::isalpha(static_cast<unsigned char>(w[1]));
}

Options parse_options(int argc, char** argv) {
  Options o;
  const std::vector<std::string> args(argv + 1, argv + argc);
  auto value = [&](std::size_t& i, const std::string& flag, const std::string& what) {
    if (i + 1 >= args.size() || is_option(args[i + 1])) throw UsageError(flag + " needs " + what);
    return args[++i];
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-in" || a == "-i") {
      o.in = value(i, a, "a file name");
      o.have_in = true;
    } else if (a == "-var" || a == "-v") {
      const std::string name = value(i, a, "a variable name and at least one value");
      std::vector<std::string> vals;
      while (i + 1 < args.size() && !is_option(args[i + 1]))
        vals.push_back(args[++i]);
      if (vals.empty()) throw UsageError(a + " " + name + " needs at least one value");
      o.vars.emplace_back(name, vals);
    } else if (a == "-log" || a == "-l") {
      o.log = value(i, a, "a file name or 'none'");
    } else if (a == "-echo" || a == "-e") {
      o.echo = value(i, a, "screen, log, both or none");
      if (o.echo != "screen" && o.echo != "log" && o.echo != "both" && o.echo != "none") {
        throw UsageError("-echo needs screen, log, both or none, got '" + o.echo + "'");
      }
    } else if (a == "-screen" || a == "-sc") {
      const std::string v = value(i, a, "'none'");
      if (v != "none") throw UsageError("-screen supports only 'none', got '" + v + "'");
      o.screen = false;
    } else if (a == "-help" || a == "-h" || a == "--help") {
      o.help = true;
    } else if (a == "-list-styles") {
      o.list_styles = true;
    } else {
      std::string msg = "unknown command-line option '" + a + "'";
      const std::string hint =
          granary::did_you_mean(a, {"-in", "-var", "-log", "-echo", "-screen", "-list-styles", "-help"});
      if (!hint.empty()) msg += "; " + hint;
      throw UsageError(msg);
    }
  }
  return o;
}

void report(int rank, granary::Engine* engine, const std::string& text) {
  if (rank != 0) return;
  std::fflush(stdout);
  std::fprintf(stderr, "ERROR: %s\n", text.c_str());
  std::fflush(stderr);
  if (engine && engine->logger) {
    engine->logger->log_only("ERROR: " + text + "\n");
    engine->logger->flush();
  }
}

void run(granary::Engine& engine, const Options& opt) {
  granary::Logger& log = *engine.logger;
  log.set_screen(opt.screen);
  if (opt.log != "none") {
    int ok = 1;
    std::string msg;
    try {
      log.open_log(opt.log, false);
    } catch (const granary::InputError& e) {
      ok = 0;
      msg = e.what();
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, engine.world);  // only rank 0 opens it
    if (!ok) throw granary::InputError(msg.empty() ? "cannot open log file '" + opt.log + "'" : msg);
  }
  log.print("Granary " GRANARY_VERSION "\n");
  granary::Input& input = *engine.input;
  if (opt.echo == "screen") input.set_echo(true, false);
  if (opt.echo == "log") input.set_echo(false, true);
  if (opt.echo == "both") input.set_echo(true, true);
  if (opt.echo == "none") input.set_echo(false, false);
  for (const auto& v : opt.vars)
    input.variables().set_command_line(v.first, v.second);
  if (opt.have_in)
    input.file(opt.in);
  else
    input.stream(std::cin, "stdin");
}

}  // namespace

int main(int argc, char** argv) {
#ifdef __GLIBC__
  // Large blocks (per-particle arrays, neighbour lists, set-up scratch) are
  // mapped and unmapped on their own. Without a fixed threshold glibc raises
  // it after the first large free, and later large blocks stay in the heap
  // after being freed: the peak memory then holds every transient at once.
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
  MPI_Init(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);

  Options opt;
  try {
    opt = parse_options(argc, argv);
  } catch (const UsageError& e) {
    if (rank == 0) std::fprintf(stderr, "ERROR: %s\n%s", e.what(), kUsage);
    MPI_Finalize();
    return 1;
  }
  if (opt.help) {
    if (rank == 0) std::fputs(kUsage, stdout);
    MPI_Finalize();
    return 0;
  }
  if (opt.list_styles) {
    if (rank == 0) {
      for (const auto& entry : granary::registered_names())
        std::printf("%s %s\n", entry.first.c_str(), entry.second.c_str());
    }
    MPI_Finalize();
    return 0;
  }

  // SIGTERM / SIGUSR1 (a batch system's time limit): finish the step, write a
  // restart, flush the files and exit with kStopStatus (doc/clusters.md)
  granary::install_stop_handlers();
  int status = 0;
  {
    std::unique_ptr<granary::Engine> engine;
    try {
      engine = std::make_unique<granary::Engine>(MPI_COMM_WORLD);
      run(*engine, opt);
      status = engine->input->quit_status();
    } catch (const granary::StopRequested& e) {
      // Raised on every rank together at the end of the step where all agreed to stop.
      if (engine && engine->logger) {
        engine->logger->print(std::string(e.what()) + "\n");
        engine->logger->flush();
      }
      status = granary::kStopStatus;
    } catch (const granary::InputError& e) {
      // Raised the same way on every rank (commands see the same input), so
      // every rank can stop cleanly.
      report(rank, engine.get(), e.what());
      status = 1;
    } catch (const granary::RunError& e) {
      // Possibly raised on this rank only: print here and stop all ranks.
      std::fflush(stdout);
      std::fprintf(stderr, "ERROR: %s\n", e.what());
      std::fflush(stderr);
      if (engine && engine->logger) {
        engine->logger->log_only(std::string("ERROR: ") + e.what() + "\n");
        engine->logger->flush();
      }
      MPI_Abort(MPI_COMM_WORLD, 1);
    } catch (const std::exception& e) {
      std::fflush(stdout);
      std::fprintf(stderr, "ERROR: unexpected failure: %s\n", e.what());
      std::fflush(stderr);
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    if (engine && engine->logger) engine->logger->flush();
  }
  MPI_Finalize();
  return status;
}
