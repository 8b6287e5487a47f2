#include "fix/fix_ave_euler.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "particles/particles.h"

namespace granary {

namespace {

const std::string kUsage = "fix ID group ave/euler nevery N cell_size_relative c parallel yes|no";

}  // namespace

Vec3 FixAveEuler::Grid::centre(int k) const {
  const int ix = k % n[0], iy = (k / n[0]) % n[1], iz = k / (n[0] * n[1]);
  return {lo[0] + (ix + 0.5) * dx[0], lo[1] + (iy + 0.5) * dx[1], lo[2] + (iz + 0.5) * dx[2]};
}

FixAveEuler::FixAveEuler(Engine& engine, const Args& args) : Fix(engine, args) {
  const std::string what = "fix " + id + " (ave/euler)";
  bool have_every = false, have_size = false, have_parallel = false;
  for (std::size_t k = 3; k < args.size(); k += 2) {
    const std::string& key = args[k];
    if (k + 1 >= args.size())
      throw InputError(what + ": keyword '" + key + "' needs a value; usage: " + kUsage);
    const std::string& val = args[k + 1];
    if (key == "nevery") {
      const long long n = parse_int(val, what + " nevery");
      if (n < 1) throw InputError(what + ": nevery must be at least 1, got " + val);
      nevery = static_cast<int>(n);
      have_every = true;
    } else if (key == "cell_size_relative") {
      cell_size_relative_ = parse_double(val, what + " cell_size_relative");
      if (!(cell_size_relative_ >= 3.0))
        throw InputError(what +
                         ": cell_size_relative must be at least 3 (cells of at least three particle "
                         "diameters), got " +
                         val);
      have_size = true;
    } else if (key == "parallel") {
      parallel_ = parse_bool(val, what + " parallel");
      have_parallel = true;
    } else if (key == "basevolume_region") {
      throw InputError(what +
                       ": basevolume_region is not supported (the volume fraction of a cell cut by a "
                       "wall is taken over the whole cell); leave it out");
    } else {
      throw InputError(what + ": unknown keyword '" + key + "'; usage: " + kUsage);
    }
  }
  if (!have_every || !have_size || !have_parallel)
    throw InputError(what + " needs the keywords nevery, cell_size_relative and parallel; usage: " + kUsage);
  // the pair part of the per-particle stress, as LIGGGHTS takes it from compute stress/atom
  stress_id_ = id + "_ave_euler_stress";
  if (engine.modify->find_compute(stress_id_)) engine.modify->delete_compute(stress_id_);
  stress_ = engine.modify->add_compute({stress_id_, args[1], "stress/atom", "pair"});
}

void FixAveEuler::unfixed() {
  if (engine_.modify->find_compute(stress_id_)) engine_.modify->delete_compute(stress_id_);
  stress_ = nullptr;
}

void FixAveEuler::init() {
  stress_ = engine_.modify->compute_or_error(stress_id_, "fix " + id + " (ave/euler)");
}

void FixAveEuler::setup() {
  evaluate();
}

void FixAveEuler::end_of_step() {
  evaluate();
}

void FixAveEuler::make_grid() {
  const Particles& p = *engine_.particles;
  const double rmax = p.max_radius(engine_.world);
  const Domain& d = *engine_.domain;
  const Vec3 lo = parallel_ ? d.sublo : d.boxlo;
  const Vec3 hi = parallel_ ? d.subhi : d.boxhi;
  const double h = cell_size_relative_ * 2.0 * rmax;
  grid_.lo = lo;
  for (int a = 0; a < 3; ++a) {
    const double L = hi[a] - lo[a];
    const double n = h > 0.0 ? std::floor(L / h) : 1.0;
    grid_.n[a] = static_cast<int>(std::clamp(n, 1.0, 1e6));
    grid_.dx[a] = L / grid_.n[a];
  }
  const double ncell = static_cast<double>(grid_.n[0]) * grid_.n[1] * grid_.n[2];
  if (ncell > 5e7)
    throw RunError("fix " + id + " (ave/euler): " + std::to_string(static_cast<long long>(ncell)) +
                   " cells; raise cell_size_relative");
}

void FixAveEuler::evaluate() {
  make_grid();
  const Particles& p = *engine_.particles;
  const int nc = grid_.cells();
  const std::size_t n = static_cast<std::size_t>(nc);
  const double vcell = grid_.dx[0] * grid_.dx[1] * grid_.dx[2];

  // the cell of each owned particle of the group (-1: not in the group)
  std::vector<int> cell(static_cast<std::size_t>(p.nlocal), -1);
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & groupbit)) continue;
    int idx[3];
    for (int a = 0; a < 3; ++a) {
      const int k = static_cast<int>(std::floor((p.x[i][a] - grid_.lo[a]) / grid_.dx[a]));
      idx[a] = std::clamp(k, 0, grid_.n[a] - 1);
    }
    cell[static_cast<std::size_t>(i)] = idx[0] + grid_.n[0] * (idx[1] + grid_.n[1] * idx[2]);
  }

  // sums per cell: mass, momentum (3), count, radius, particle volume
  const int nsum = 7;
  std::vector<double> sums(nsum * n, 0.0);
  for (int i = 0; i < p.nlocal; ++i) {
    const int c = cell[static_cast<std::size_t>(i)];
    if (c < 0) continue;
    double* s = &sums[nsum * static_cast<std::size_t>(c)];
    const double m = p.rmass[i], r = p.radius[i];
    s[0] += m;
    s[1] += m * p.v[i][0];
    s[2] += m * p.v[i][1];
    s[3] += m * p.v[i][2];
    s[4] += 1.0;
    s[5] += r;
    s[6] += 4.0 / 3.0 * M_PI * r * r * r;
  }
  if (!parallel_)
    MPI_Allreduce(MPI_IN_PLACE, sums.data(), static_cast<int>(sums.size()), MPI_DOUBLE, MPI_SUM,
                  engine_.world);

  v_avg.assign(3 * n, 0.0);
  volumefraction.assign(n, 0.0);
  radius.assign(n, 0.0);
  pressure.assign(n, 0.0);
  for (std::size_t c = 0; c < n; ++c) {
    const double* s = &sums[nsum * c];
    if (s[4] == 0.0) continue;  // empty: zeros
    for (int a = 0; a < 3; ++a)
      v_avg[3 * c + a] = s[1 + a] / s[0];
    radius[c] = s[5] / s[4];
    volumefraction[c] = s[6] / vcell;
  }

  // pressure: -1/3 trace of (pair stress of compute stress/atom - kinetic part with v - v_avg)
  stress_->compute_peratom();
  stress_->invoked_peratom = engine_.update->ntimestep;
  const auto& S = stress_->array_atom;
  for (int i = 0; i < p.nlocal; ++i) {
    const int c = cell[static_cast<std::size_t>(i)];
    if (c < 0) continue;
    const double* va = &v_avg[3 * static_cast<std::size_t>(c)];
    double kin = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double dv = p.v[i][a] - va[a];
      kin += p.rmass[i] * dv * dv;
    }
    const double trace = S[0][static_cast<std::size_t>(i)] + S[1][static_cast<std::size_t>(i)] +
                         S[2][static_cast<std::size_t>(i)] - kin;
    pressure[static_cast<std::size_t>(c)] -= trace;
  }
  if (!parallel_) MPI_Allreduce(MPI_IN_PLACE, pressure.data(), nc, MPI_DOUBLE, MPI_SUM, engine_.world);
  for (double& pr : pressure)
    pr /= 3.0 * vcell;
  computed_step_ = engine_.update->ntimestep;
}

GRANARY_FIX_STYLE("ave/euler", FixAveEuler);

}  // namespace granary
