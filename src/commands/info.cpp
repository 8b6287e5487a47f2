// The info command: the state of the running program, by category, on the
// screen, in the log or in a file (doc/commands/info.md).
#include <mpi.h>

#include <sys/utsname.h>
#include <vtkVersionMacros.h>

#include <Eigen/Core>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <cstring>
#include <sstream>
#include <string>

#include "comm/comm.h"
#include "compute/compute.h"
#include "contact/lane.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "output/vtk_module.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "neighbor/neighbor.h"
#include "output/dump.h"
#include "output/output.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* const kCategories =
    "all, system, communication, computes, dumps, fixes, groups, regions, variables, time, configuration";

// The wall-clock time when the program started (the first engine built).
const auto kStart = std::chrono::steady_clock::now();

std::string join_words(const Args& w) {
  std::string s;
  for (const auto& x : w)
    s += " " + x;
  return s;
}

std::string group_name(const Engine& e, int igroup) {
  return igroup >= 0 && igroup < Groups::kMaxGroups ? e.groups->names[igroup] : "?";
}

void system_info(Engine& e, std::ostringstream& o) {
  const Domain& d = *e.domain;
  o << "\nSystem information:\n";
  o << "Units      = " << d.units << "\n";
  o << "Atom style = granular\n";
  o << "Atoms      = " << e.particles->natoms << ", types = " << e.particles->ntypes << "\n";
  if (d.box_exist) {
    o << "Orthogonal box = (" << d.boxlo[0] << " " << d.boxlo[1] << " " << d.boxlo[2] << ") to ("
      << d.boxhi[0] << " " << d.boxhi[1] << " " << d.boxhi[2] << ")\n";
    o << "Boundaries = ";
    for (int k = 0; k < 3; ++k)
      o << d.boundary[k][0] << (d.boundary[k][1] != d.boundary[k][0] ? std::string(1, d.boundary[k][1]) : "")
        << (k < 2 ? "," : "\n");
  } else {
    o << "Box has not yet been created\n";
  }
  o << "Pair style = " << e.force->pair_style << join_words(e.force->pair_words) << "\n";
  o << "Newton pair = " << (e.force->newton_pair ? "on" : "off") << "\n";
  o << "Timestep = " << e.update->dt << " s, step = " << e.update->ntimestep << "\n";
  o << "Neighbor skin = " << e.neighbor->skin << " m, every " << e.neighbor->every << " delay "
    << e.neighbor->delay << " check " << (e.neighbor->check ? "yes" : "no") << "\n";
}

void communication_info(Engine& e, std::ostringstream& o) {
  char version[MPI_MAX_LIBRARY_VERSION_STRING];
  int len = 0;
  MPI_Get_library_version(version, &len);
  // Open MPI counts the terminating NUL in len: a NUL in the text would cut
  // the printed report short there
  std::string v(version, strnlen(version, static_cast<std::size_t>(len)));
  if (const auto nl = v.find('\n'); nl != std::string::npos) v.resize(nl);
  while (!v.empty() && (v.back() == ',' || v.back() == ' '))
    v.pop_back();
  int major = 0, minor = 0;
  MPI_Get_version(&major, &minor);
  o << "\nCommunication information:\n";
  o << "MPI library level: MPI v" << major << "." << minor << "\n";
  o << "MPI version: " << v << "\n";
  o << "MPI ranks = " << e.nprocs << ", OpenMP threads = 1\n";
  const Comm& c = *e.comm;
  o << "Processor grid = " << c.procgrid[0] << " x " << c.procgrid[1] << " x " << c.procgrid[2] << "\n";
  o << "Communication style = "
    << (c.tiled() ? (c.rcb_tree().empty() ? "tiled (the grid's boxes)" : "tiled (rcb boxes)") : "brick")
    << "\n";
  o << "Communication mode = single, ghost velocities = yes\n";
  o << "Ghost cutoff = " << c.cutghost << " m (user " << c.cutghost_user << " m)\n";
}

void computes_info(Engine& e, std::ostringstream& o) {
  o << "\nCompute information:\n";
  int k = 0;
  for (const auto& c : e.modify->computes)
    o << "Compute[" << k++ << "]: " << c->id << ", style = " << c->style
      << ", group = " << group_name(e, c->igroup) << "\n";
}

void dumps_info(Engine& e, std::ostringstream& o) {
  o << "\nDump information:\n";
  int k = 0;
  for (const auto& d : e.output->dumps)
    o << "Dump[" << k++ << "]: " << d->id << ", file = " << d->filename << ", style = " << d->style
      << ", group = " << group_name(e, d->igroup) << ", every = " << d->every << "\n";
}

void fixes_info(Engine& e, std::ostringstream& o) {
  o << "\nFix information:\n";
  int k = 0;
  for (const auto& f : e.modify->fixes)
    o << "Fix[" << k++ << "]: " << f->id << ", style = " << f->style
      << ", group = " << group_name(e, f->igroup) << "\n";
}

void groups_info(Engine& e, std::ostringstream& o) {
  o << "\nGroup information:\n";
  for (int g = 0; g < Groups::kMaxGroups; ++g)
    if (!e.groups->names[g].empty()) o << "Group[" << g << "]: " << e.groups->names[g] << "\n";
}

void regions_info(Engine& e, std::ostringstream& o) {
  o << "\nRegion information:\n";
  int k = 0;
  for (const auto& r : e.domain->regions)
    o << "Region[" << k++ << "]: " << r->id << ", style = " << r->style << "\n";
}

void variables_info(Engine& e, std::ostringstream& o) {
  o << "\nVariable information:\n";
  Variables& v = e.input->variables();
  int k = 0;
  for (const auto& name : v.names()) {
    const std::string style = v.style(name);
    o << "Variable[" << k++ << "]: " << name << ", style = " << style;
    if (style == "index" || style == "loop" || style == "string" || style == "world" || style == "universe" ||
        style == "uloop" || style == "internal")
      o << ", value = " << v.retrieve(name);
    o << "\n";
  }
}

void time_info(Engine& e, std::ostringstream& o) {
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - kStart).count();
  const double cpu = static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
  double cpu_max = 0.0;
  MPI_Allreduce(&cpu, &cpu_max, 1, MPI_DOUBLE, MPI_MAX, e.world);
  auto hms = [](double s) {
    char b[32];
    const long t = static_cast<long>(s);
    std::snprintf(b, sizeof b, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
    return std::string(b);
  };
  o << "\nTotal time information (MPI rank 0):\n";
  o << "  CPU time: " << hms(cpu) << " (largest over the ranks " << hms(cpu_max) << ")\n";
  o << " Wall time: " << hms(wall) << "\n";
}

void configuration_info(std::ostringstream& o) {
  utsname u{};
  o << "\nConfiguration information:\n";
  if (uname(&u) == 0) o << "Operating system: " << u.sysname << " " << u.release << " " << u.machine << "\n";
#ifdef GRANARY_VERSION
  o << "Granary version: " << GRANARY_VERSION << "\n";
#endif
  o << "Compiler: "
#if defined(__clang__)
    << "Clang " << __clang_major__ << "." << __clang_minor__ << "." << __clang_patchlevel__
#elif defined(__GNUC__)
    << "GNU C++ " << __GNUC__ << "." << __GNUC_MINOR__ << "." << __GNUC_PATCHLEVEL__
#else
    << "unknown"
#endif
    << ", C++ standard " << __cplusplus << "\n";
  // the instruction set of the build (CMake option GRANARY_SIMD) and the
  // contacts the contact kernels evaluate at once
  o << "Packed instructions: "
#if defined(__AVX2__)
    << "AVX2"
#elif defined(__SSE2__)
    << "SSE2"
#else
    << "the compiler's default"
#endif
    << ", " << contact::lane::width<contact::lane::Wide>() << " contacts at a time\n";
  o << "Libraries: VTK " << VTK_VERSION << ", Eigen " << EIGEN_WORLD_VERSION << "." << EIGEN_MAJOR_VERSION
    << "." << EIGEN_MINOR_VERSION << "\n";
  o << "VTK output module: "
    << (vtk_module_path().empty() ? std::string("not loaded (loaded by the first VTK dump)")
                                  : vtk_module_path())
    << "\n";
#ifdef NDEBUG
  o << "Assertions: off\n";
#else
  o << "Assertions: on\n";
#endif
}

void cmd_info(Engine& e, const Args& a) {
  if (a.empty()) throw InputError(std::string("info needs one or more of: ") + kCategories + " [out WHERE]");
  enum class Out { Screen, Log, Append, Overwrite } out = Out::Screen;
  std::string file;
  unsigned want = 0;
  const char* names[] = {"system", "communication", "computes",  "dumps", "fixes",
                         "groups", "regions",       "variables", "time",  "configuration"};
  constexpr unsigned kAll = (1u << 10) - 1;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (a[k] == "out") {
      if (k + 1 >= a.size())
        throw InputError("info out needs a destination: screen, log, append FILE or overwrite FILE");
      const std::string& w = a[++k];
      if (w == "screen") {
        out = Out::Screen;
      } else if (w == "log") {
        out = Out::Log;
      } else if (w == "append" || w == "overwrite") {
        if (k + 1 >= a.size()) throw InputError("info out " + w + " needs a file name");
        out = w == "append" ? Out::Append : Out::Overwrite;
        file = a[++k];
      } else {
        throw InputError("info out '" + w + "': expected screen, log, append FILE or overwrite FILE");
      }
      continue;
    }
    if (a[k] == "all") {
      want |= kAll;
      continue;
    }
    bool known = false;
    for (unsigned c = 0; c < 10; ++c)
      if (a[k] == names[c]) {
        want |= 1u << c;
        known = true;
      }
    if (!known) throw InputError("info: unknown category '" + a[k] + "'; expected " + kCategories);
  }
  std::ostringstream o;
  o.precision(8);
  o << "\nInfo-Info-Info-Info-Info-Info-Info-Info-Info-Info-Info\n";
  o << "Printed on " <<
      [] {
        const std::time_t t = std::time(nullptr);
        char b[64];
        std::strftime(b, sizeof b, "%a %b %d %H:%M:%S %Y", std::localtime(&t));
        return std::string(b);
      }()
    << "\n";
  if (want & 1u) system_info(e, o);
  if (want & 2u) communication_info(e, o);
  if (want & 4u) computes_info(e, o);
  if (want & 8u) dumps_info(e, o);
  if (want & 16u) fixes_info(e, o);
  if (want & 32u) groups_info(e, o);
  if (want & 64u) regions_info(e, o);
  if (want & 128u) variables_info(e, o);
  if (want & 256u) time_info(e, o);
  if (want & 512u) configuration_info(o);
  o << "\nInfo-Info-Info-Info-Info-Info-Info-Info-Info-Info-Info\n\n";
  const std::string text = o.str();
  switch (out) {
    case Out::Screen:
      e.logger->screen_only(text);
      break;
    case Out::Log:
      e.logger->log_only(text);
      break;
    default: {
      // rank 0 writes; every rank learns whether it could
      int ok = 1;
      if (e.rank == 0) {
        std::ofstream f(file, out == Out::Append ? std::ios::app : std::ios::trunc);
        f << text;
        ok = f.good() ? 1 : 0;
      }
      MPI_Bcast(&ok, 1, MPI_INT, 0, e.world);
      if (!ok) throw InputError("info: cannot write to '" + file + "'; check that its folder exists");
    }
  }
}

}  // namespace

GRANARY_COMMAND("info", cmd_info);

}  // namespace granary
