#include "core/modify.h"

#include <mpi.h>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "fix/fix.h"
#include "fix/fix_property_global.h"

namespace granary {

Modify::Modify(Engine& engine) : engine_(engine) {}
Modify::~Modify() = default;

namespace {
template <class Registry>
const typename std::remove_reference<decltype(*Registry::instance().find(""))>::type& factory_or_error(
    const std::string& kind, const std::string& style) {
  const auto& registry = Registry::instance();
  const auto* factory = registry.find(style);
  if (!factory) {
    std::string msg = "unknown " + kind + " style '" + style + "'";
    const std::string hint = did_you_mean(style, registry.names());
    throw InputError(msg + (hint.empty() ? "; see doc/" + kind + "es for the list" : "; " + hint));
  }
  return *factory;
}
}  // namespace

Fix* Modify::add_fix(const Args& args) {
  if (args.size() < 3) throw InputError("usage: fix ID group-ID style args...");
  const auto& factory = factory_or_error<FixRegistry>("fix", args[2]);
  std::unique_ptr<Fix> fix = factory(engine_, args);
  Fix* raw = fix.get();
  for (auto& existing : fixes) {
    if (existing->id == args[0]) {
      if (existing->style != args[2]) {
        throw InputError("fix ID '" + args[0] + "' is already a " + existing->style +
                         " fix; unfix it first or use another ID");
      }
      existing = std::move(fix);
      rebuild_hook_lists();
      return raw;
    }
  }
  fixes.push_back(std::move(fix));
  rebuild_hook_lists();
  auto state = restart_states.find(raw->id);
  if (state != restart_states.end() && state->second.style == raw->style && raw->restart_global) {
    raw->unpack_restart(state->second.data);
    engine_.logger->print("Restored the state of fix " + raw->id + " from the restart file\n");
    restart_states.erase(state);
  }
  return raw;
}

void Modify::delete_fix(const std::string& id) {
  for (auto it = fixes.begin(); it != fixes.end(); ++it) {
    if ((*it)->id == id) {
      (*it)->unfixed();
      fixes.erase(it);
      rebuild_hook_lists();
      return;
    }
  }
  if (Fix* f = find_fix(id))
    throw InputError("unfix " + id + ": that is another name of fix " + f->id + "; unfix " + f->id);
  fix_or_error(id, "unfix");
}

Fix* Modify::find_fix(const std::string& id) const {
  for (const auto& f : fixes)
    if (f->id == id) return f.get();
  for (const auto& f : fixes)
    for (const auto& a : f->aliases)
      if (a == id) return f.get();
  return nullptr;
}

Fix* Modify::fix_or_error(const std::string& id, const std::string& what) const {
  if (Fix* f = find_fix(id)) return f;
  std::vector<std::string> known;
  for (const auto& f : fixes)
    known.push_back(f->id);
  const std::string hint = did_you_mean(id, known);
  throw InputError("unknown fix ID '" + id + "' in " + what + (hint.empty() ? "" : "; " + hint));
}

Fix* Modify::find_fix_by_style(const std::string& style) const {
  for (const auto& f : fixes)
    if (f->style == style) return f.get();
  return nullptr;
}

Compute* Modify::add_compute(const Args& args) {
  if (args.size() < 3) throw InputError("usage: compute ID group-ID style args...");
  if (find_compute(args[0])) {
    throw InputError("compute ID '" + args[0] + "' is already used; uncompute it first or use another ID");
  }
  const auto& factory = factory_or_error<ComputeRegistry>("compute", args[2]);
  computes.push_back(factory(engine_, args));
  return computes.back().get();
}

void Modify::delete_compute(const std::string& id) {
  for (auto it = computes.begin(); it != computes.end(); ++it) {
    if ((*it)->id == id) {
      (*it)->uncomputed();
      computes.erase(it);
      return;
    }
  }
  compute_or_error(id, "uncompute");
}

Compute* Modify::find_compute(const std::string& id) const {
  for (const auto& c : computes)
    if (c->id == id) return c.get();
  return nullptr;
}

Compute* Modify::compute_or_error(const std::string& id, const std::string& what) const {
  if (Compute* c = find_compute(id)) return c;
  std::vector<std::string> known;
  for (const auto& c : computes)
    known.push_back(c->id);
  const std::string hint = did_you_mean(id, known);
  throw InputError("unknown compute ID '" + id + "' in " + what + (hint.empty() ? "" : "; " + hint));
}

void Modify::rebuild_hook_lists() {
  for (auto* list : {&initial_integrate_, &post_integrate_, &pre_exchange_, &pre_neighbor_, &post_neighbor_,
                     &pre_force_, &post_force_, &final_integrate_, &end_of_step_}) {
    list->clear();
  }
  for (const auto& f : fixes) {
    const unsigned h = f->hooks();
    if (h & Fix::INITIAL_INTEGRATE) initial_integrate_.push_back(f.get());
    if (h & Fix::POST_INTEGRATE) post_integrate_.push_back(f.get());
    if (h & Fix::PRE_EXCHANGE) pre_exchange_.push_back(f.get());
    if (h & Fix::PRE_NEIGHBOR) pre_neighbor_.push_back(f.get());
    if (h & Fix::POST_NEIGHBOR) post_neighbor_.push_back(f.get());
    if (h & Fix::PRE_FORCE) pre_force_.push_back(f.get());
    if (h & Fix::POST_FORCE) post_force_.push_back(f.get());
    if (h & Fix::FINAL_INTEGRATE) final_integrate_.push_back(f.get());
    if (h & Fix::END_OF_STEP) end_of_step_.push_back(f.get());
  }
}

void Modify::init() {
  rebuild_hook_lists();
  for (auto& f : fixes)
    f->init();
  for (auto& c : computes) {
    c->init();
    c->invoked_scalar = c->invoked_vector = c->invoked_peratom = c->invoked_local = -1;
  }
}

void Modify::setup() {
  for (auto& f : fixes)
    f->setup();
}
namespace {
// Calls one hook of a fix and adds its wall time to the fix's run_time.
void timed(Fix* f, void (Fix::*hook)()) {
  const double t0 = MPI_Wtime();
  (f->*hook)();
  f->run_time += MPI_Wtime() - t0;
}
}  // namespace

void Modify::initial_integrate() {
  for (Fix* f : initial_integrate_)
    timed(f, &Fix::initial_integrate);
}
void Modify::post_integrate() {
  for (Fix* f : post_integrate_)
    timed(f, &Fix::post_integrate);
}
void Modify::pre_exchange() {
  for (Fix* f : pre_exchange_)
    timed(f, &Fix::pre_exchange);
}
void Modify::pre_neighbor() {
  for (Fix* f : pre_neighbor_)
    timed(f, &Fix::pre_neighbor);
}
void Modify::post_neighbor() {
  for (Fix* f : post_neighbor_)
    timed(f, &Fix::post_neighbor);
}
void Modify::pre_force() {
  for (Fix* f : pre_force_)
    timed(f, &Fix::pre_force);
}
void Modify::post_force() {
  for (Fix* f : post_force_)
    timed(f, &Fix::post_force);
}
void Modify::final_integrate() {
  for (Fix* f : final_integrate_)
    timed(f, &Fix::final_integrate);
}
void Modify::end_of_step(std::int64_t step) {
  for (Fix* f : end_of_step_) {
    if (step % f->nevery == 0) timed(f, &Fix::end_of_step);
  }
}
bool Modify::end_of_step_due(std::int64_t step) const {
  for (const Fix* f : end_of_step_)
    if (f->end_of_step_due(step)) return true;
  return false;
}

void Modify::reset_dt() {
  for (auto& f : fixes)
    f->reset_dt();
}

const GlobalProperty* Modify::find_property(const std::string& name) const {
  return FixPropertyGlobal::find(*this, name);
}

const GlobalProperty& Modify::require_property(const std::string& name, const std::string& needed_by) const {
  return *FixPropertyGlobal::require(*this, name, needed_by);
}

std::string Modify::group_user(int igroup) const {
  for (const auto& f : fixes)
    if (f->igroup == igroup) return "fix " + f->id;
  for (const auto& c : computes)
    if (c->igroup == igroup) return "compute " + c->id;
  return "";
}

bool Modify::has_integrator() const {
  for (const auto& f : fixes)
    if (f->time_integrate) return true;
  return false;
}

}  // namespace granary
