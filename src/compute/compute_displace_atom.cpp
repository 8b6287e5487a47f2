// compute ID group displace/atom: per particle of the group, its displacement
// from its original position (dx, dy, dz, |d|) with both positions unwrapped
// across periodic boundaries, a per-atom array of 4 columns [m]; 0 for
// particles outside the group. compute ID group msd [com yes|no]: the mean
// over the group of dx^2, dy^2, dz^2 and |d|^2, a global vector of 4 [m^2];
// with com yes the displacement of the group's centre of mass is taken out
// first (the original centre from the original positions of the group's
// particles). Original positions: domain/origin_field.h.
#include <mpi.h>

#include <cmath>
#include <memory>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/groups.h"
#include "domain/origin_field.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeDisplaceAtom : public Compute {
 public:
  ComputeDisplaceAtom(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 3, 3, "compute ID group-ID displace/atom");
    peratom_flag = true;
    peratom_cols = 4;
    origin_ = std::make_unique<OriginField>(engine, "origin/" + id);
  }

  void uncomputed() override { origin_->release(); }

  void compute_peratom() override {
    const Particles& p = *engine_.particles;
    array_atom.assign(4, std::vector<double>(p.nlocal, 0.0));
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const Vec3 d = engine_.groups->unwrapped(i) - origin_->at(i);
      for (int c = 0; c < 3; ++c)
        array_atom[c][i] = d[c];
      array_atom[3][i] = d.norm();
    }
  }

 private:
  std::unique_ptr<OriginField> origin_;
};

// compute ID group msd/nongauss [com yes|no]: the same displacements, as the
// global vector <dr^2>, <dr^4> and the non-Gaussian parameter
// 3 <dr^4> / (5 <dr^2>^2) - 1 (0 when <dr^2> is 0).
class ComputeMSD : public Compute {
 public:
  ComputeMSD(Engine& engine, const Args& args) : Compute(engine, args) {
    nongauss_ = style == "msd/nongauss";
    const std::string usage = "compute ID group-ID " + style + " [com yes|no]";
    if (args.size() != 3 && args.size() != 5)
      throw InputError("wrong number of arguments for compute " + id + " " + style + "; usage: " + usage);
    if (args.size() == 5) {
      if (args[3] != "com")
        throw InputError("unknown compute " + style + " keyword '" + args[3] + "'; usage: " + usage);
      com_ = parse_bool(args[4], "compute " + style + " com");
    }
    size_vector = nongauss_ ? 3 : 4;
    vector.assign(size_vector, 0.0);
    origin_ = std::make_unique<OriginField>(engine, "origin/" + id);
  }

  void uncomputed() override { origin_->release(); }

  void compute_vector() override {
    const Particles& p = *engine_.particles;
    // the displacement of the group's centre of mass (com yes)
    Vec3 drift(0, 0, 0);
    if (com_) {
      double local[7] = {0, 0, 0, 0, 0, 0, 0};
      for (int i = 0; i < p.nlocal; ++i) {
        if (!(p.mask[i] & groupbit)) continue;
        const Vec3 xu = engine_.groups->unwrapped(i), x0 = origin_->at(i);
        for (int c = 0; c < 3; ++c) {
          local[c] += p.rmass[i] * xu[c];
          local[3 + c] += p.rmass[i] * x0[c];
        }
        local[6] += p.rmass[i];
      }
      double all[7];
      MPI_Allreduce(local, all, 7, MPI_DOUBLE, MPI_SUM, engine_.world);
      if (all[6] > 0.0) drift = Vec3(all[0] - all[3], all[1] - all[4], all[2] - all[5]) / all[6];
    }
    double local[6] = {0, 0, 0, 0, 0, 0};  // dx^2 dy^2 dz^2 dr^2 count dr^4
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const Vec3 d = engine_.groups->unwrapped(i) - origin_->at(i) - drift;
      for (int c = 0; c < 3; ++c)
        local[c] += d[c] * d[c];
      local[3] += d.squaredNorm();
      local[4] += 1.0;
      local[5] += d.squaredNorm() * d.squaredNorm();
    }
    double all[6];
    MPI_Allreduce(local, all, 6, MPI_DOUBLE, MPI_SUM, engine_.world);
    const double n = all[4];
    if (nongauss_) {
      const double r2 = n > 0.0 ? all[3] / n : 0.0, r4 = n > 0.0 ? all[5] / n : 0.0;
      vector = {r2, r4, r2 > 0.0 ? 3.0 * r4 / (5.0 * r2 * r2) - 1.0 : 0.0};
      return;
    }
    for (int k = 0; k < 4; ++k)
      vector[k] = n > 0.0 ? all[k] / n : 0.0;
  }

 private:
  std::unique_ptr<OriginField> origin_;
  bool com_ = false, nongauss_ = false;
};

}  // namespace

GRANARY_COMPUTE_STYLE("displace/atom", ComputeDisplaceAtom);
GRANARY_COMPUTE_STYLE("msd", ComputeMSD);
GRANARY_COMPUTE_STYLE("msd/nongauss", ComputeMSD);

}  // namespace granary
