// An engine driven by script lines, quiet on screen: the common scaffolding of
// tests that set up a scene with commands.
#pragma once

#include <mpi.h>

#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "particles/particles.h"

namespace granary::test {

struct ScriptEngine {
  granary::Engine e;
  explicit ScriptEngine(MPI_Comm comm = MPI_COMM_SELF) : e(comm) { e.logger->set_screen(false); }
  /// Execute one script line.
  void cmd(const std::string& line) { e.input->one(line); }
  /// Execute script lines in order.
  void cmds(const std::vector<std::string>& lines) {
    for (const auto& l : lines)
      cmd(l);
  }
  void lines(const std::vector<std::string>& script) { cmds(script); }
  const granary::Particles& p() const { return *e.particles; }
};

}  // namespace granary::test

#include <filesystem>

namespace granary::test {

/// A mkstemp/mkdtemp template ("<temp dir>/<prefix>XXXXXX") as a writable,
/// zero-terminated buffer.
inline std::vector<char> temp_template(const std::string& prefix) {
  const std::string t = (std::filesystem::temp_directory_path() / (prefix + "XXXXXX")).string();
  std::vector<char> buf(t.begin(), t.end());
  buf.push_back('\0');
  return buf;
}

}  // namespace granary::test
