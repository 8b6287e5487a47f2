// A minimal Engine for the input fuzzer: a logger, the real Input and the
// input-language commands, and nothing of the simulation. Commands that would
// touch files are refused, and every input gets a budget of commands so that
// loops in random scripts end.
#include <mpi.h>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/registry.h"
#include "fuzz_engine_stub.h"

// The simulation subsystems are not part of the fuzzed code: CMake generates
// an empty class for each one that engine.h declares.
#include "fuzz_subsystems.h"

namespace granary {

Engine::Engine(MPI_Comm world_) : world(world_) {
  MPI_Comm_rank(world, &rank);
  MPI_Comm_size(world, &nprocs);
  logger = std::make_unique<Logger>(rank);
  logger->set_screen(false);
  input = std::make_unique<Input>(*this);
}

Engine::~Engine() {
  input.reset();
  logger.reset();
}

void Engine::clear() {}
void Engine::create_subsystems() {}
void Engine::destroy_subsystems() {}

void Engine::execute(const Args& words) {
  if (words.empty()) return;
  if (--fuzz::command_budget < 0) throw InputError("fuzz: command budget used up");
  for (const auto& w : words) {
    if (w.size() > 100000) throw InputError("fuzz: word too long");
  }
  const std::string& cmd = words[0];
  if (cmd == "include" || cmd == "log") throw InputError("fuzz: " + cmd + " is not run");
  if (cmd == "jump" && words.size() > 1 && words[1] != "SELF") throw InputError("fuzz: jump to a file");
  if (cmd == "print") {
    for (const auto& w : words) {
      if (w == "file" || w == "append") throw InputError("fuzz: print to a file");
    }
  }
  if (cmd == "variable" && words.size() > 2 && words[2] == "file") throw InputError("fuzz: file variable");
  const CommandFn* fn = CommandRegistry::instance().find(cmd);
  if (!fn) throw InputError("unknown command '" + cmd + "'");
  (*fn)(*this, Args(words.begin() + 1, words.end()));
}

double Engine::thermo_keyword(const std::string& name, bool& found) {
  found = true;
  if (name == "step") return 50;
  if (name == "__beginstep") return 0;
  if (name == "__endstep") return 100;
  if (name == "dt") return 0.001;
  if (name == "atoms") return 3;
  found = false;
  return 0.0;
}

double Engine::compute_value(const std::string& id, int) {
  throw InputError("no compute " + id);
}
double Engine::fix_value(const std::string& id, int) {
  throw InputError("no fix " + id);
}
double Engine::group_function(const std::string& name, const Args& args) {
  if (args.empty()) throw InputError(name + "() needs a group");
  return static_cast<double>(args.size());
}

bool Engine::atom_vector(const std::string& name, std::vector<double>& out) {
  if (name == "id")
    out = {1, 2, 3};
  else if (name == "x")
    out = {0.5, -1.0, 2.0};
  else if (name == "mass")
    out = {1.0, 2.0, 0.0};
  else
    return false;
  return true;
}

void Engine::compute_peratom(const std::string& id, int col, std::vector<double>& out) {
  if (col > 2) throw InputError("no column");
  out = {1.0 * col, 2.0, 3.0};
  if (id.size() > 3) throw InputError("no compute " + id);
}

void Engine::fix_peratom(const std::string& id, int col, std::vector<double>& out) {
  compute_peratom(id, col, out);
}

}  // namespace granary
