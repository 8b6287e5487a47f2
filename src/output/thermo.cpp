#include "output/thermo.h"

#include <mpi.h>

#include <cmath>
#include <cstdio>

#include "compute/kinetic_energy.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "particles/particles.h"

namespace granary {

Thermo::Thermo(Engine& engine) : engine_(engine) {
  wall_start = MPI_Wtime();
}

void Thermo::style_command(const Args& args) {
  if (args.empty()) throw InputError("usage: thermo_style one|custom keyword ...");
  if (args[0] == "one") {
    keywords = {"step", "atoms", "ke", "cpu"};
    return;
  }
  if (args[0] != "custom") throw InputError("thermo_style must be one or custom, got '" + args[0] + "'");
  if (args.size() < 2) throw InputError("thermo_style custom needs at least one keyword");
  keywords.assign(args.begin() + 1, args.end());
  // Validate keyword names now so typos fail at the command, not at the run.
  for (const auto& k : keywords) {
    if (k.rfind("c_", 0) == 0 || k.rfind("f_", 0) == 0 || k.rfind("v_", 0) == 0) continue;
    static const std::vector<std::string> known = {
        "step", "elapsed", "elaplong", "dt",  "time", "cpu", "atoms", "ke",    "vol",       "lx",  "ly",
        "lz",   "xlo",     "xhi",      "ylo", "yhi",  "zlo", "zhi",   "spcpu", "cpuremain", "part"};
    bool ok = false;
    for (const auto& n : known)
      ok |= n == k;
    if (!ok) {
      const std::string hint = did_you_mean(k, known);
      throw InputError("unknown thermo keyword '" + k + "'" + (hint.empty() ? "" : "; " + hint));
    }
  }
}

void Thermo::modify_command(const Args& args) {
  if (args.empty()) throw InputError("usage: thermo_modify keyword value ...");
  for (std::size_t k = 0; k < args.size(); ++k) {
    const std::string& w = args[k];
    if (k + 1 >= args.size()) throw InputError("thermo_modify " + w + " needs a value");
    const std::string& v = args[++k];
    if (w == "lost") {
      if (v == "error")
        lost = Lost::Error;
      else if (v == "warn")
        lost = Lost::Warn;
      else if (v == "ignore")
        lost = Lost::Ignore;
      else
        throw InputError("thermo_modify lost takes error, warn or ignore, got '" + v + "'");
    } else if (w == "norm") {
      norm = parse_bool(v, "thermo_modify norm");
    } else if (w == "flush") {
      flush = parse_bool(v, "thermo_modify flush");
    } else if (w == "format") {
      if (v == "float") {
        if (k + 1 >= args.size()) throw InputError("thermo_modify format float needs a format");
        format_float = args[++k];
      } else if (v == "int") {
        if (k + 1 >= args.size()) throw InputError("thermo_modify format int needs a format");
        format_int = args[++k];
      } else {
        throw InputError("thermo_modify format takes float or int here");
      }
    } else if (w == "lost/bond" || w == "temp" || w == "press" || w == "every") {
      // accepted for compatibility; no effect for granular runs
    } else {
      throw InputError("unknown thermo_modify keyword '" + w + "'; expected lost, norm, flush or format");
    }
  }
}

namespace {
std::string column_name(const std::string& k) {
  if (k == "step") return "Step";
  if (k == "atoms") return "Atoms";
  if (k == "ke") return "KinEng";
  if (k == "time") return "Time";
  if (k == "dt") return "Dt";
  if (k == "cpu") return "CPU";
  if (k == "vol") return "Volume";
  if (k == "elapsed") return "Elapsed";
  return k;
}
}  // namespace

void Thermo::header() {
  std::string line;
  for (const auto& k : keywords) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%s", line.empty() ? "" : " ", column_name(k).c_str());
    line += buf;
  }
  engine_.logger->print(line + "\n");
}

double Thermo::keyword_value(const std::string& key, bool& found) {
  Engine& e = engine_;
  const Update& u = *e.update;
  const Domain& d = *e.domain;
  found = true;
  if (key == "step" || key == "elapsed" || key == "elaplong") {
    if (key == "step") return static_cast<double>(u.ntimestep);
    return static_cast<double>(u.ntimestep - u.firststep);
  }
  if (key == "dt") return u.dt;
  if (key == "time") return u.time();
  if (key == "cpu") return MPI_Wtime() - wall_start;
  if (key == "spcpu" || key == "cpuremain") {
    // steps per second of wall time in the current run, and the time it still needs
    const double elapsed = u.running ? MPI_Wtime() - u.loop_start_wall : 0.0;
    const double done = static_cast<double>(u.ntimestep - u.firststep);
    const double rate = elapsed > 0 && done > 0 ? done / elapsed : 0.0;
    if (key == "spcpu") return rate;
    return rate > 0 ? static_cast<double>(u.laststep - u.ntimestep) / rate : 0.0;
  }
  if (key == "atoms") return static_cast<double>(u.count_global());
  if (key == "ke") {
    const double total = kinetic_translational(e, 1, nullptr);  // group all
    if (norm) {
      const double n = static_cast<double>(u.count_global());
      return n > 0 ? total / n : 0.0;
    }
    return total;
  }
  if (key == "vol") return d.volume();
  if (key == "lx") return d.prd[0];
  if (key == "ly") return d.prd[1];
  if (key == "lz") return d.prd[2];
  if (key == "xlo") return d.boxlo[0];
  if (key == "xhi") return d.boxhi[0];
  if (key == "ylo") return d.boxlo[1];
  if (key == "yhi") return d.boxhi[1];
  if (key == "zlo") return d.boxlo[2];
  if (key == "zhi") return d.boxhi[2];
  if (key == "part") return e.rank;
  if (key == "__beginstep") return static_cast<double>(u.beginstep);
  if (key == "__endstep") return static_cast<double>(u.endstep);
  found = false;
  return 0.0;
}

namespace {
// c_ID, c_ID[2], f_ID[1], v_name
double reference_value(Engine& e, const std::string& key) {
  std::string name = key.substr(2);
  int index = 0;
  const auto bracket = name.find('[');
  if (bracket != std::string::npos) {
    if (name.back() != ']') throw InputError("thermo keyword '" + key + "' has an unclosed [");
    index = static_cast<int>(parse_int(name.substr(bracket + 1, name.size() - bracket - 2), key));
    name = name.substr(0, bracket);
  }
  if (key[0] == 'c') return e.compute_value(name, index);
  if (key[0] == 'f') return e.fix_value(name, index);
  return e.input->variables().compute_equal(name);
}
}  // namespace

void Thermo::line() {
  std::string out;
  for (const auto& k : keywords) {
    double value = 0.0;
    bool integer = false;
    if (k.size() > 2 && (k.rfind("c_", 0) == 0 || k.rfind("f_", 0) == 0 || k.rfind("v_", 0) == 0)) {
      value = reference_value(engine_, k);
    } else {
      bool found = false;
      value = keyword_value(k, found);
      if (!found) throw InputError("unknown thermo keyword '" + k + "'");
      integer = k == "step" || k == "atoms" || k == "elapsed" || k == "elaplong";
    }
    char buf[64];
    if (integer)
      std::snprintf(buf, sizeof buf, format_int.c_str(), static_cast<long long>(value));
    else
      std::snprintf(buf, sizeof buf, format_float.c_str(), value);
    out += (out.empty() ? "" : " ");
    out += buf;
  }
  engine_.logger->print(out + "\n");
  if (flush) engine_.logger->flush();
}

// A progress line at most every 10 s of wall time during long runs (the run
// loop calls this every few steps; only rank 0 looks at the clock).
void Thermo::progress() {
  Engine& e = engine_;
  const Update& u = *e.update;
  if (!u.running || e.rank != 0) return;
  const double now = MPI_Wtime();
  if (last_progress_ < u.loop_start_wall) last_progress_ = u.loop_start_wall;
  if (now - last_progress_ < 10.0) return;
  last_progress_ = now;
  const double run_start_ = u.loop_start_wall;
  const double done = static_cast<double>(u.ntimestep - u.firststep);
  const double total = static_cast<double>(u.laststep - u.firststep);
  const double rate = done / std::max(now - run_start_, 1e-9);
  const double left = rate > 0 ? (total - done) / rate : 0.0;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "Progress: step %lld of %lld (%.1f%%), simulated time %.6g s, %.4g steps/s, "
                "about %.0f s left\n",
                static_cast<long long>(u.ntimestep), static_cast<long long>(u.laststep),
                total > 0 ? 100.0 * done / total : 100.0, u.time(), rate, left);
  e.logger->print(buf);
  e.logger->flush();
}

void cmd_thermo(Engine& e, const Args& a) {
  require_args(a, 1, 1, "thermo N");
  const auto n = parse_int(a[0], "thermo");
  if (n < 0) throw InputError("thermo needs N >= 0");
  e.thermo->every = static_cast<int>(n);
}
void cmd_thermo_style(Engine& e, const Args& a) {
  e.thermo->style_command(a);
}
void cmd_thermo_modify(Engine& e, const Args& a) {
  e.thermo->modify_command(a);
}
GRANARY_COMMAND("thermo", cmd_thermo);
GRANARY_COMMAND("thermo_style", cmd_thermo_style);
GRANARY_COMMAND("thermo_modify", cmd_thermo_modify);

}  // namespace granary
