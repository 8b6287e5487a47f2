// libFuzzer targets that run the whole engine: the file readers behind a few
// steps of a small simulation, and small random scripts. One source, four
// targets (GRANARY_FUZZ_MODE picks what the input is):
//   fuzz_restart  the bytes of a restart file, read with read_restart and run
//                 for a few steps. When the input's first byte is odd, the
//                 harness first rewrites the section and table checksums (if
//                 the header and table are whole), so that mutations reach the
//                 section parsers instead of the checksum test.
//   fuzz_stl      the bytes of an STL file (ASCII or binary), a wall of
//                 fix mesh/surface that a few spheres fall on.
//   fuzz_clump    a clump sphere file ("x y z r" per line), inserted as two
//                 bodies of fix multisphere that fall for a few steps.
//   fuzz_run      a whole input script, run with budgets (commands, steps,
//                 particles) in a private working directory; words that leave
//                 it (an absolute path, "..") and `shell` are refused.
// Every input runs in a fresh Engine on one rank. InputError and RunError are
// the answers bad input should get; an "internal error" (an exception without
// its own message), a crash, a sanitizer report or a hang is a bug.
#include <mpi.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/resources.h"
#include "core/stop_signal.h"

#ifndef GRANARY_FUZZ_MODE
#error "GRANARY_FUZZ_MODE must be 1 (restart), 2 (STL), 3 (clump) or 4 (script)"
#endif

namespace {

namespace fs = std::filesystem;

constexpr int kMaxCommands = 300;  // commands per input (loops end)
constexpr long kMaxSteps = 400;    // timesteps per input
constexpr double kMaxParticles = 3000;

std::string g_dir;   // private working folder of this process: every input runs in it
std::string g_home;  // the folder libFuzzer was started in (corpus, artifacts)

// Budgets and the sandbox of fuzz_run; the other modes run fixed scripts.
struct Guard {
  int commands = 0;
  long steps = 0;
  bool sandbox = false;

  static bool leaves_folder(const std::string& w) {
    return (!w.empty() && (w[0] == '/' || w[0] == '~')) || w.find("..") != std::string::npos;
  }
  void operator()(const granary::Args& words) {
    if (++commands > kMaxCommands) throw granary::InputError("fuzz: command budget used up");
    const std::string& cmd = words[0];
    if (sandbox) {
      if (cmd == "shell") throw granary::InputError("fuzz: shell is not run");
      for (const auto& w : words)
        if (leaves_folder(w)) throw granary::InputError("fuzz: a path outside the working folder");
    }
    if (cmd == "run" || cmd == "rerun") {
      if (words.size() < 2) return;  // the command's own error
      char* end = nullptr;
      const double n = std::strtod(words[1].c_str(), &end);
      if (end == words[1].c_str() || !(n >= 0) || n > kMaxSteps)
        throw granary::InputError("fuzz: run too long");
      for (std::size_t k = 2; k < words.size(); ++k)
        if (words[k] == "every") throw granary::InputError("fuzz: run every is not run");
      steps += static_cast<long>(n);
      if (steps > kMaxSteps) throw granary::InputError("fuzz: step budget used up");
    }
  }
};

void write_file(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

// Standard CRC-32 (reflected, polynomial 0xEDB88320), as the restart format uses.
std::uint32_t crc32(const char* p, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= static_cast<unsigned char>(p[i]);
    for (int k = 0; k < 8; ++k)
      c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xFFFFFFFFu;
}

// Rewrite the checksums of a restart file whose header and section table are
// whole (layout in doc/restart_format.md); leave anything else as it is.
void repair_restart_checksums(std::string& b) {
  const std::size_t head = 32, name = 32, entry = name + 8 + 8 + 4 + 4;
  if (b.size() < head) return;
  std::uint32_t n;
  std::memcpy(&n, b.data() + 24, 4);
  if (n > 64 || b.size() < head + n * entry) return;
  for (std::uint32_t k = 0; k < n; ++k) {
    char* t = &b[head + k * entry];
    std::uint64_t off, size;
    std::memcpy(&off, t + name, 8);
    std::memcpy(&size, t + name + 8, 8);
    if (off > b.size() || size > b.size() - off) continue;
    const std::uint32_t c = crc32(b.data() + off, size);
    std::memcpy(t + name + 16, &c, 4);
  }
  const std::uint32_t c = crc32(b.data() + head, n * entry);
  std::memcpy(&b[28], &c, 4);
}

// The fixed script of the reader targets; FILE is the fuzzed file.
std::string reader_script(const std::uint8_t* data, std::size_t size) {
  const std::string box =
      "atom_style granular\natom_modify map array\nboundary f f f\nnewton off\nunits si\n"
      "region box block -0.05 0.05 -0.05 0.05 -0.05 0.05 units box\ncreate_box 1 box\n"
      "neighbor 0.002 bin\nneigh_modify delay 0\n"
      "fix m1 all property/global youngsModulus peratomtype 5e6\n"
      "fix m2 all property/global poissonsRatio peratomtype 0.45\n"
      "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n"
      "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n"
      "pair_style gran model hertz tangential history\npair_coeff * *\ntimestep 1e-5\n"
      "fix g all gravity 9.81 vector 0 0 -1\n";
#if GRANARY_FUZZ_MODE == 1
  (void)box;
  std::string bytes(reinterpret_cast<const char*>(data), size);
  if (size > 0 && (data[0] & 1u)) repair_restart_checksums(bytes);
  write_file("fuzz.restart", reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  return "read_restart fuzz.restart\nfix integr all nve/sphere\nthermo 1\nrun 5\n";
#elif GRANARY_FUZZ_MODE == 2
  write_file("fuzz.stl", data, size);
  return box +
         "fix mesh all mesh/surface file fuzz.stl type 1\n"
         "fix wall all wall/gran model hertz tangential history mesh n_meshes 1 meshes mesh\n"
         "create_atoms 1 single 0 0 0.01 units box\ncreate_atoms 1 single 0.01 0 0.0 units box\n"
         "set atom * diameter 0.004 density 2500\nvelocity all set 0 0 -1\n"
         "fix integr all nve/sphere\nthermo 1\nrun 5\n";
#else
  // nspheres is the number of lines that hold a number, so that the count check
  // is not the only thing reached
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::string line;
  int lines = 0;
  while (std::getline(in, line))
    if (line.find_first_of("0123456789") != std::string::npos) ++lines;
  write_file("fuzz.clump", data, size);
  return box +
         "fix pts all particletemplate/multisphere 15485867 atom_type 1 density constant 1190 nspheres " +
         std::to_string(lines < 1 ? 1 : lines) +
         " ntry 200 spheres file fuzz.clump scale 1.0 type 1\n"
         "fix pdd all particledistribution/discrete 49979687 1 pts 1.0\n"
         "fix ms all multisphere\n"
         "region fill block -0.04 0.04 -0.04 0.04 -0.04 0.04 units box\n"
         "fix ins all insert/pack seed 32452867 distributiontemplate pdd maxattempt 20 insert_every once "
         "overlapcheck yes all_in yes orientation random region fill particles_in_region 2\n"
         "thermo 1\nrun 5\n";
#endif
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  MPI_Init(argc, argv);
  char tmpl[] = "/tmp/granary-fuzz-XXXXXX";
  if (!mkdtemp(tmpl)) {
    std::perror("mkdtemp");
    std::abort();
  }
  g_dir = tmpl;
  g_home = fs::current_path().string();
  granary::set_particle_limit(kMaxParticles);
  std::atexit([] {
    std::error_code ec;
    fs::remove_all(g_dir, ec);
  });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 65536) return -1;  // keeps each input quick; the readers are not size-limited
  // a clean folder for every input (what a script writes stays in it)
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(g_dir, ec))
    fs::remove_all(entry.path(), ec);
  if (chdir(g_dir.c_str()) != 0) std::abort();
  std::string script;
#if GRANARY_FUZZ_MODE == 4
  script.assign(reinterpret_cast<const char*>(data), size);
#else
  script = reader_script(data, size);
#endif
  auto engine = std::make_unique<granary::Engine>(MPI_COMM_WORLD);
  engine->logger->set_screen(false);
  Guard guard;
  guard.sandbox = GRANARY_FUZZ_MODE == 4;
  engine->command_guard = [&guard](const granary::Args& w) { guard(w); };
  std::istringstream in(script);
  try {
    engine->input->stream(in, "fuzz");
  } catch (const granary::InputError&) {
  } catch (const granary::StopRequested&) {
  } catch (const granary::RunError& e) {
    // "internal error: ..." is how the input layer names an exception that
    // carried no message of its own: a bug, not an answer
    if (std::strstr(e.what(), "internal error:")) {
      std::fprintf(stderr, "fuzz: %s\n", e.what());
      std::abort();
    }
  }
  engine.reset();
  if (chdir(g_home.c_str()) != 0) std::abort();
  return 0;
}
