#include "core/engine.h"

#include "comm/comm.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "core/modify.h"
#include "neighbor/contact_history.h"
#include "neighbor/neighbor.h"
#include "output/output.h"
#include "output/thermo.h"
#include "core/force.h"
#include "pair/pair.h"
#include "particles/particles.h"

namespace granary {

Engine::Engine(MPI_Comm world_) : world(world_) {
  MPI_Comm_rank(world, &rank);
  MPI_Comm_size(world, &nprocs);
  logger = std::make_unique<Logger>(rank);
  input = std::make_unique<Input>(*this);
  create_subsystems();
}

Engine::~Engine() {
  destroy_subsystems();
  input.reset();
  logger.reset();
}

// Order matters: see the comment in engine.h. Later subsystems may refer to
// earlier ones in their constructors, never the reverse.
void Engine::create_subsystems() {
  particles = std::make_unique<Particles>();
  domain = std::make_unique<Domain>(*this);
  groups = std::make_unique<Groups>(*this);
  comm = std::make_unique<Comm>(*this);
  neighbor = std::make_unique<Neighbor>(*this);
  force = std::make_unique<Force>(*this);
  modify = std::make_unique<Modify>(*this);
  update = std::make_unique<Update>(*this);
  thermo = std::make_unique<Thermo>(*this);
  output = std::make_unique<Output>(*this);
}

// Reverse order of creation: fixes and computes may refer to everything else.
void Engine::destroy_subsystems() {
  output.reset();
  thermo.reset();
  update.reset();
  modify.reset();
  force.reset();
  neighbor.reset();
  comm.reset();
  groups.reset();
  domain.reset();
  particles.reset();
}

void Engine::delete_particle(int i) {
  ContactHistory* history = force->contact_history();
  if (history) history->forget_particle(particles->id[i]);
  particles->remove_local(i);
}

long long Engine::delete_particles(const std::vector<char>& doomed) {
  long long n = 0;
  for (int i = particles->nlocal - 1; i >= 0; --i) {
    if (!doomed[i]) continue;
    delete_particle(i);
    ++n;
  }
  return n;
}

void Engine::clear() {
  destroy_subsystems();
  create_subsystems();
}

void Engine::execute(const Args& words) {
  if (words.empty()) return;
  if (command_guard) command_guard(words);
  const auto& registry = CommandRegistry::instance();
  const CommandFn* fn = registry.find(words[0]);
  if (!fn) {
    std::string msg = "unknown command '" + words[0] + "'";
    const std::string hint = did_you_mean(words[0], registry.names());
    if (!hint.empty())
      msg += "; " + hint;
    else
      msg += "; see doc/commands for the list of commands";
    throw InputError(msg);
  }
  Args rest(words.begin() + 1, words.end());
  (*fn)(*this, rest);
}

void Engine::input_line(const std::string& line) {
  input->one(line);
}

}  // namespace granary
