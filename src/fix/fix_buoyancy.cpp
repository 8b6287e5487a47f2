// fix ID group buoyancy level L dim x|y|z density RHO [region R] (LIGGGHTS):
// the weight of the displaced fluid, rho_f |g| V_sub, against gravity, on each
// particle of the group, where V_sub is the volume of the particle below the
// fluid's surface (the plane dim = L; "below" along the gravity of fix
// gravity, which must point along dim): a whole sphere 4/3 pi r^3, a cap of
// depth h pi h^2 (3r - h) / 3, nothing above the surface. With region R only
// particles whose centre lies in R. The global vector is the total buoyancy
// force [N]. Applied after the pair forces every step and at the start of a
// run. See doc/fixes/buoyancy.md.
#include <mpi.h>

#include <algorithm>
#include <cmath>

#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixBuoyancy : public Fix {
 public:
  FixBuoyancy(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage = "fix ID group buoyancy level L dim x|y|z density RHO [region R]";
    bool have_dim = false, have_level = false, have_density = false;
    for (std::size_t k = 3; k < args.size(); k += 2) {
      if (k + 1 >= args.size()) throw InputError("fix " + id + " buoyancy: '" + args[k] + "' needs a value");
      const std::string& key = args[k];
      const std::string& v = args[k + 1];
      if (key == "level") {
        level_ = parse_double(v, "the fluid level of fix " + id);
        have_level = true;
      } else if (key == "dim") {
        if (v != "x" && v != "y" && v != "z")
          throw InputError("fix " + id + " buoyancy: dim must be x, y or z, got '" + v + "'");
        dim_ = v[0] - 'x';
        have_dim = true;
      } else if (key == "density") {
        density_ = parse_double(v, "the fluid density of fix " + id);
        if (!(density_ >= 0.0)) throw InputError("fix " + id + " buoyancy: the density must not be negative");
        have_density = true;
      } else if (key == "region") {
        engine.domain->region_or_error(v, "fix " + id + " buoyancy");
        region_ = v;
      } else {
        throw InputError("unknown fix buoyancy keyword '" + key + "'; usage: " + usage);
      }
    }
    if (!have_dim || !have_level || !have_density)
      throw InputError("fix " + id + " buoyancy needs level, dim and density; usage: " + usage);
    size_vector = 3;
  }

  unsigned hooks() const override { return POST_FORCE; }

  void init() override {
    const Fix* g = engine_.modify->find_fix_by_style("gravity");
    if (!g)
      throw InputError("fix " + id + " buoyancy needs a fix gravity (buoyancy is the weight of the fluid)");
    gravity_id_ = g->id;
  }

  void post_force() override {
    Fix* g = engine_.modify->fix_or_error(gravity_id_, "fix " + id + " buoyancy");
    Vec3 acc;
    for (int d = 0; d < 3; ++d)
      acc[d] = g->compute_vector(d);
    const double gmag = acc.norm();
    for (int d = 0; d < 3; ++d) {
      if (d != dim_ && std::fabs(acc[d]) > 1e-12 * gmag)
        throw InputError("fix " + id + " buoyancy: the gravity of fix " + gravity_id_ + " must point along " +
                         std::string(1, "xyz"[dim_]) + " (dim)");
    }
    total_ = Vec3(0, 0, 0);
    if (gmag == 0.0) return;
    const double down = acc[dim_] < 0.0 ? -1.0 : 1.0;  // the fluid lies on this side of the level
    const Region* region = region_.empty() ? nullptr : engine_.domain->region_or_error(region_, "fix " + id);
    Particles& p = *engine_.particles;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit) || (region && !region->match(p.x[i]))) continue;
      const double r = p.radius[i];
      // depth of the sphere's lowest point below the level, capped at the diameter
      const double h = std::clamp(down * (p.x[i][dim_] - level_) + r, 0.0, 2.0 * r);
      const double volume = M_PI * h * h * (3.0 * r - h) / 3.0;
      const Vec3 f = (-density_ * volume) * acc;
      p.f[i] += f;
      total_ += f;
    }
  }

  double compute_vector(int i) override {
    if (i < 0 || i > 2) return 0.0;
    double all = 0.0;
    MPI_Allreduce(&total_[i], &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    return all;
  }

 private:
  double level_ = 0.0, density_ = 0.0;
  int dim_ = 2;
  std::string region_, gravity_id_;
  Vec3 total_{0, 0, 0};
};

}  // namespace

GRANARY_FIX_STYLE("buoyancy", FixBuoyancy);

}  // namespace granary
