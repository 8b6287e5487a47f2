// The delete_atoms command: delete particles by group, region or fraction (whole clumps with mol yes).

#include <algorithm>
#include <unordered_set>

#include "comm/collectives.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "domain/region.h"
#include "particles/clumps.h"
#include "neighbor/contact_history.h"
#include "pair/pair.h"
#include "particles/particles.h"

#include "commands/particle_commands.h"

namespace granary {

namespace {

using namespace particle_commands;

void cmd_delete_atoms(Engine& e, const Args& a) {
  const char* usage =
      "delete_atoms group GROUP | region REGION | porosity REGION FRACTION SEED  [compress yes|no] [mol "
      "yes|no]";
  begin(e, a, 2, "delete_atoms", usage);
  Particles& p = *e.particles;
  const std::string& style = a[0];
  std::size_t first = 2;
  int bit = 0;
  const Region* region = nullptr;
  double fraction = 0.0;
  long long seed = 0;
  if (style == "group") {
    bit = e.groups->bitmask(e.groups->find_or_error(a[1], "delete_atoms"));
  } else if (style == "region") {
    region = e.domain->region_or_error(a[1], "delete_atoms");
  } else if (style == "porosity") {
    if (a.size() < 4)
      throw InputError(std::string("delete_atoms porosity needs REGION FRACTION SEED; usage: ") + usage);
    region = e.domain->region_or_error(a[1], "delete_atoms porosity");
    fraction = parse_double(a[2], "delete_atoms porosity fraction");
    seed = parse_int(a[3], "delete_atoms porosity seed");
    if (fraction < 0.0 || fraction > 1.0)
      throw InputError("delete_atoms porosity needs a fraction in [0, 1]");
    if (seed <= 0) throw InputError("delete_atoms porosity needs a positive seed");
    first = 4;
  } else if (style == "overlap") {
    throw InputError("delete_atoms overlap is not supported; use create_atoms random with overlap instead");
  } else {
    const std::string hint = did_you_mean(style, {"group", "region", "porosity"});
    throw InputError("unknown delete_atoms style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                     "; usage: " + usage);
  }
  bool compress = true, mol = false;
  for (std::size_t k = first; k < a.size(); k += 2) {
    if (k + 1 >= a.size()) throw InputError("delete_atoms keyword '" + a[k] + "' needs a value");
    if (a[k] == "compress")
      compress = parse_bool(a[k + 1], "delete_atoms compress");
    else if (a[k] == "mol")
      mol = parse_bool(a[k + 1], "delete_atoms mol");
    else
      throw InputError("unknown delete_atoms keyword '" + a[k] + "'; usage: " + usage);
  }

  const long long before = sum_all(e, p.nlocal);
  std::vector<char> doomed(p.nlocal, 0);
  std::vector<tagint> gone_bodies;
  for (int i = 0; i < p.nlocal; ++i) {
    if (style == "group")
      doomed[i] = (p.mask[i] & bit) != 0;
    else if (style == "region")
      doomed[i] = region->match(p.x[i]);
    else
      doomed[i] = region->match(p.x[i]) && hash01(seed, p.id[i]) < fraction;
  }
  if (mol) {
    // whole clumps go: every particle sharing a body id with a deleted one
    std::vector<long long> bodies;
    for (int i = 0; i < p.nlocal; ++i)
      if (doomed[i] && p.body[i] >= 0) bodies.push_back(static_cast<long long>(p.body[i]));
    std::vector<long long> all = allgather(e.world, bodies);
    const std::unordered_set<long long> gone(all.begin(), all.end());
    gone_bodies.assign(gone.begin(), gone.end());
    for (int i = 0; i < p.nlocal; ++i)
      if (p.body[i] >= 0 && gone.count(static_cast<long long>(p.body[i]))) doomed[i] = 1;
  }
  e.delete_particles(doomed);
  p.clear_ghosts();
  // whole clumps removed: their body records go too
  if (mol && !gone_bodies.empty())
    if (e.clumps) e.clumps->remove_bodies(gone_bodies);

  {
    // surviving ids on every rank; with compress they become 1..N in the
    // order of the old ids (independent of the rank count)
    std::vector<long long> mine(p.nlocal);
    for (int i = 0; i < p.nlocal; ++i)
      mine[i] = static_cast<long long>(p.id[i]);
    std::vector<long long> all = allgather(e.world, mine);
    std::sort(all.begin(), all.end());
    // contact history between runs is keyed by ids: drop entries of deleted
    // particles (their ids may be used again) and follow the renumbering
    if (e.force->pair && e.force->pair->history()) e.force->pair->history()->retain(all, compress);
    if (compress) {
      for (int i = 0; i < p.nlocal; ++i) {
        p.id[i] = static_cast<tagint>(std::lower_bound(all.begin(), all.end(), mine[i]) - all.begin() + 1);
      }
    }
  }
  particles_changed(e);
  const long long after = static_cast<long long>(p.natoms);
  e.logger->print("Deleted " + std::to_string(before - after) +
                  " atoms, new total = " + std::to_string(after) + "\n");
}

}  // namespace

GRANARY_COMMAND("delete_atoms", cmd_delete_atoms);

}  // namespace granary
