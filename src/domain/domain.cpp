#include "domain/domain.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/style_list.h"
#include "domain/region.h"
#include "particles/particles.h"

namespace granary {

Domain::Domain(Engine& engine) : engine_(engine) {}
Domain::~Domain() = default;

void Domain::set_box(const Vec3& lo, const Vec3& hi) {
  for (int d = 0; d < 3; ++d) {
    if (!(hi[d] > lo[d])) {
      throw InputError("box is empty along " + std::string(1, "xyz"[d]) +
                       ": the upper bound must exceed the lower bound");
    }
  }
  boxlo = lo;
  boxhi = hi;
  minlo = lo;
  minhi = hi;
  prd = hi - lo;
  box_exist = true;
}

void Domain::reset_box() {
  bool shrink = false;
  for (int d = 0; d < 3; ++d)
    for (int s = 0; s < 2; ++s)
      shrink |= boundary[d][s] == 's' || boundary[d][s] == 'm';
  if (!shrink) return;
  const Particles& p = *engine_.particles;
  double ext[6];  // -min x,y,z then max x,y,z (so one MAX reduction does both)
  for (int d = 0; d < 3; ++d)
    ext[d] = ext[d + 3] = -std::numeric_limits<double>::max();
  for (int i = 0; i < p.nlocal; ++i) {
    for (int d = 0; d < 3; ++d) {
      ext[d] = std::max(ext[d], -(p.x[i][d] - p.radius[i]));
      ext[d + 3] = std::max(ext[d + 3], p.x[i][d] + p.radius[i]);
    }
  }
  double all[6];
  MPI_Allreduce(ext, all, 6, MPI_DOUBLE, MPI_MAX, engine_.world);
  const bool empty = all[3] < -0.5 * std::numeric_limits<double>::max();
  for (int d = 0; d < 3; ++d) {
    const double small = 1.0e-6 * (minhi[d] - minlo[d]);
    if (boundary[d][0] == 's') boxlo[d] = empty ? minlo[d] : -all[d] - small;
    if (boundary[d][0] == 'm') boxlo[d] = empty ? minlo[d] : std::min(minlo[d], -all[d] - small);
    if (boundary[d][1] == 's') boxhi[d] = empty ? minhi[d] : all[d + 3] + small;
    if (boundary[d][1] == 'm') boxhi[d] = empty ? minhi[d] : std::max(minhi[d], all[d + 3] + small);
    prd[d] = boxhi[d] - boxlo[d];
  }
}

void Domain::remap(Vec3& x, int& image) const {
  int ix, iy, iz;
  Particles::image_unpack(image, ix, iy, iz);
  int* img[3] = {&ix, &iy, &iz};
  for (int d = 0; d < 3; ++d) {
    if (!periodic[d]) continue;
    if (!std::isfinite(x[d])) continue;  // a blown-up particle: the run's checks report it
    // more than one box length away (a particle far too fast): whole lengths at
    // once, so the loops below take at most a step (one length is the common
    // case and gives the same arithmetic as the loops)
    const double s = std::floor((x[d] - boxlo[d]) / prd[d]);
    if (s < -1.0 || s > 1.0) {
      x[d] -= s * prd[d];
      // image counts wrap (10 bits each), so a multiple of 2^20 changes nothing
      *img[d] += static_cast<int>(std::fmod(s, 1048576.0));
      // beyond 2^52 lengths the subtraction cannot place it: left where it is
      if (x[d] < boxlo[d] - prd[d] || x[d] >= boxhi[d] + prd[d]) continue;
    }
    while (x[d] < boxlo[d]) {
      x[d] += prd[d];
      --*img[d];
    }
    while (x[d] >= boxhi[d]) {
      x[d] -= prd[d];
      ++*img[d];
    }
  }
  image = Particles::image_pack(ix, iy, iz);
}

bool Domain::inside_box(const Vec3& x) const {
  for (int d = 0; d < 3; ++d)
    if (x[d] < boxlo[d] || x[d] > boxhi[d]) return false;
  return true;
}

void Domain::add_region(const std::vector<std::string>& args) {
  if (args.size() < 2) throw InputError("usage: region ID style args... [side in|out] [units box|lattice]");
  if (args[1] == kRegionDeleteWord) {
    delete_region(args[0]);
    return;
  }
  if (find_region(args[0])) {
    throw InputError("region ID '" + args[0] + "' is already used; pick another ID or delete it first");
  }
  const auto& registry = RegionRegistry::instance();
  const RegionFactory* factory = registry.find(args[1]);
  if (!factory) {
    std::string msg = "unknown region style '" + args[1] + "'";
    const std::string hint = did_you_mean(args[1], registry.names());
    throw InputError(msg + (hint.empty() ? "" : "; " + hint));
  }
  regions.push_back((*factory)(engine_, args));
}

void Domain::delete_region(const std::string& id) {
  for (const auto& r : regions)
    if (r->uses(id))
      throw InputError("cannot delete region '" + id + "': region " + r->id + " (" + r->style +
                       ") is made of it; delete " + r->id + " first");
  for (auto it = regions.begin(); it != regions.end(); ++it) {
    if ((*it)->id == id) {
      regions.erase(it);
      return;
    }
  }
  throw InputError("cannot delete unknown region '" + id + "'");
}

Region* Domain::find_region(const std::string& id) const {
  for (const auto& r : regions)
    if (r->id == id) return r.get();
  return nullptr;
}

Region* Domain::region_or_error(const std::string& id, const std::string& what) const {
  Region* r = find_region(id);
  if (r) return r;
  std::vector<std::string> known;
  for (const auto& reg : regions)
    known.push_back(reg->id);
  std::string msg = "unknown region '" + id + "' in " + what;
  const std::string hint = did_you_mean(id, known);
  throw InputError(msg + (hint.empty() ? "; define it first with the region command" : "; " + hint));
}

}  // namespace granary
