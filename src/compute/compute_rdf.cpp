// compute ID group rdf Nbin [itype1 jtype1 itype2 jtype2 ...]: the radial
// distribution function g(r) and the coordination number of the particles of
// the group (LIGGGHTS 3.8 / LAMMPS syntax and output), as a global array of
// Nbin rows: column 1 the bin centre r, then per type pair g(r) and the
// coordination number. The bins cover 0 .. the largest pair cutoff, twice the
// largest particle radius (LIGGGHTS' granular force cutoff).
//
// Every particle I of the group with a type in itypeN counts, for each
// particle J != I of the group with a type in jtypeN whose centre is closer
// than the cutoff, one entry in the bin of their distance (pairs are found
// from the owned and ghost particles with a cell list, so periodic images
// count). With N_I the particles of types itypeN, N_J those of jtypeN and V
// the box volume, g(r) is the count of a bin over N_I N_J V_shell / V,
// V_shell the volume of the bin's shell (as LIGGGHTS 3.8 normalises it: a
// particle is not excluded from its own type's count, so for an ideal gas
// g tends to 1 - 1/N_J where the types overlap), and the coordination number
// the cumulative count over N_I (the mean number of J particles within the
// bin's outer radius of an I particle). See doc/computes/rdf.md.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/utils.h"
#include "domain/domain.h"
#include "geometry/sphere_grid.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeRDF : public Compute {
 public:
  ComputeRDF(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID rdf Nbin [itype1 jtype1 itype2 jtype2 ...]";
    const std::string what = "compute " + id + " rdf";
    if (args.size() < 4) throw InputError(what + ": missing Nbin; usage: " + usage);
    const long long nbin = parse_int(args[3], what + " Nbin");
    if (nbin < 1 || nbin > 10000000) throw InputError(what + ": Nbin must be at least 1, got " + args[3]);
    nbin_ = static_cast<int>(nbin);
    if ((args.size() - 4) % 2 != 0)
      throw InputError(what + ": the type arguments come in pairs (itype jtype); usage: " + usage);
    const int ntypes = engine.particles->ntypes;
    for (std::size_t k = 4; k + 1 < args.size(); k += 2) {
      Pair pr;
      parse_type_range(args[k], ntypes, pr.ilo, pr.ihi);
      parse_type_range(args[k + 1], ntypes, pr.jlo, pr.jhi);
      pairs_.push_back(pr);
    }
    if (pairs_.empty()) pairs_.push_back({1, ntypes, 1, ntypes});
    size_array_rows = nbin_;
    size_array_cols = 1 + 2 * static_cast<int>(pairs_.size());
  }

  void compute_array() override {
    const Particles& p = *engine_.particles;
    const double rmax = p.max_radius(engine_.world);
    if (!(rmax > 0.0))
      throw RunError("compute " + id +
                     " rdf: there are no particles (the bins reach twice the largest radius)");
    const double cutoff = 2.0 * rmax;
    require_ghost_reach(cutoff);
    const double delr = cutoff / nbin_;
    const std::size_t npairs = pairs_.size();

    // histogram: one entry per ordered (I, J) pair and matching type pair
    std::vector<double> hist(npairs * static_cast<std::size_t>(nbin_), 0.0);
    const double half = 0.5 * cutoff;
    SphereGrid grid(*engine_.domain, half);
    for (int j = 0; j < p.size(); ++j)
      grid.add(p.x[j], half);
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const int ti = p.type[i];
      grid.visit_overlapping(p.x[i], half, false, [&](int j) {
        if (j == i || !(p.mask[j] & groupbit)) return false;
        const double d = (p.x[j] - p.x[i]).norm();
        if (d >= cutoff) return false;
        const int bin = std::min(nbin_ - 1, static_cast<int>(d / delr));
        const int tj = p.type[j];
        for (std::size_t m = 0; m < npairs; ++m) {
          const Pair& pr = pairs_[m];
          if (ti >= pr.ilo && ti <= pr.ihi && tj >= pr.jlo && tj <= pr.jhi)
            hist[m * static_cast<std::size_t>(nbin_) + static_cast<std::size_t>(bin)] += 1.0;
        }
        return false;
      });
    }
    MPI_Allreduce(MPI_IN_PLACE, hist.data(), static_cast<int>(hist.size()), MPI_DOUBLE, MPI_SUM,
                  engine_.world);

    // particles of the group in each range (N_I, N_J)
    std::vector<double> counts(2 * npairs, 0.0);
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const int t = p.type[i];
      for (std::size_t m = 0; m < npairs; ++m) {
        const Pair& pr = pairs_[m];
        counts[2 * m] += t >= pr.ilo && t <= pr.ihi;
        counts[2 * m + 1] += t >= pr.jlo && t <= pr.jhi;
      }
    }
    MPI_Allreduce(MPI_IN_PLACE, counts.data(), static_cast<int>(counts.size()), MPI_DOUBLE, MPI_SUM,
                  engine_.world);

    const Domain& dom = *engine_.domain;
    const double volume = dom.prd[0] * dom.prd[1] * dom.prd[2];
    const int ncol = size_array_cols;
    array.assign(static_cast<std::size_t>(nbin_) * ncol, 0.0);
    for (int b = 0; b < nbin_; ++b)
      array[static_cast<std::size_t>(b) * ncol] = (b + 0.5) * delr;
    for (std::size_t m = 0; m < npairs; ++m) {
      const double ni = counts[2 * m], nj = counts[2 * m + 1];
      const double pairs_expected = ni * nj;
      double cumulative = 0.0;
      for (int b = 0; b < nbin_; ++b) {
        const double rlo = b * delr, rhi = (b + 1) * delr;
        const double shell = 4.0 / 3.0 * M_PI * (rhi * rhi * rhi - rlo * rlo * rlo);
        const double h = hist[m * static_cast<std::size_t>(nbin_) + static_cast<std::size_t>(b)];
        const double expected = pairs_expected * shell / volume;
        cumulative += h;
        double* row = &array[static_cast<std::size_t>(b) * ncol];
        row[1 + 2 * m] = expected > 0.0 ? h / expected : 0.0;
        row[2 + 2 * m] = ni > 0.0 ? cumulative / ni : 0.0;
      }
    }
  }

 private:
  struct Pair {
    int ilo, ihi, jlo, jhi;
  };
  int nbin_ = 0;
  std::vector<Pair> pairs_;
};

}  // namespace

GRANARY_COMPUTE_STYLE("rdf", ComputeRDF);

}  // namespace granary
