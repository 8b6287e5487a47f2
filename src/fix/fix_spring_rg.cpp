// fix ID group spring/rg K RG0: a harmonic restraint on the radius of gyration
// Rg of the group, Rg^2 = sum m_i |x_i - xcm|^2 / M (positions unwrapped
// across periodic boundaries), with the energy E = K (Rg - RG0)^2 and its
// forces F_i = -dE/dx_i = -2 K (1 - RG0 / Rg) (m_i / M) (x_i - xcm), which sum
// to zero. RG0 NULL: the group's Rg when the fix is defined. Global scalar: E.
#include <mpi.h>

#include <cmath>
#include <string>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/groups.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixSpringRg : public Fix {
 public:
  FixSpringRg(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage = "fix ID group spring/rg K RG0 (RG0 = NULL: the current radius of gyration)";
    require_args(args, 5, 5, usage);
    k_ = parse_double(args[3], "the spring constant K of fix " + id + " spring/rg");
    if (!(k_ > 0.0)) throw InputError("fix " + id + " spring/rg: K must be positive, got " + args[3]);
    if (args[4] == "NULL") {
      if (!(engine.groups->mass(igroup) > 0.0))
        throw InputError("fix " + id + " spring/rg: RG0 NULL needs particles in group " + args[1] +
                         " (their radius of gyration is the target)");
      rg0_ = gyration(engine.groups->xcm(igroup), engine.groups->mass(igroup));
    } else {
      rg0_ = parse_double(args[4], "RG0 of fix " + id + " spring/rg");
      if (!(rg0_ >= 0.0))
        throw InputError("fix " + id + " spring/rg: RG0 must be >= 0 or NULL, got " + args[4]);
    }
    scalar_flag = true;
  }

  unsigned hooks() const override { return POST_FORCE; }

  void post_force() override {
    Groups& g = *engine_.groups;
    const double mass = g.mass(igroup);
    energy_ = 0.0;
    if (!(mass > 0.0)) return;
    const Vec3 xcm = g.xcm(igroup);
    const double rg = gyration(xcm, mass);
    energy_ = k_ * (rg - rg0_) * (rg - rg0_);
    if (!(rg > 0.0)) return;  // all particles at one point: no direction
    const double term = 2.0 * k_ * (1.0 - rg0_ / rg) / mass;
    Particles& p = *engine_.particles;
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & groupbit) p.f[i] -= (term * p.rmass[i]) * (g.unwrapped(i) - xcm);
  }

  double compute_scalar() override { return energy_; }

 private:
  // the group's radius of gyration about xcm (collective)
  double gyration(const Vec3& xcm, double mass) const {
    const Particles& p = *engine_.particles;
    double local = 0.0, all = 0.0;
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & groupbit) local += p.rmass[i] * (engine_.groups->unwrapped(i) - xcm).squaredNorm();
    MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    return std::sqrt(all / mass);
  }

  double k_ = 0.0, rg0_ = 0.0, energy_ = 0.0;
};

}  // namespace

GRANARY_FIX_STYLE("spring/rg", FixSpringRg);

}  // namespace granary
