// compute ID group coord/atom CUTOFF [mix yes|no] [typeN ...]: per particle of
// the group, the number of particles (of any group) whose centre lies closer
// than CUTOFF to its own; with typeN ranges one count per range, with
// mix yes only particles of another type. 0 for particles outside the group.
// Found by a cell list over the owned and ghost particles at each evaluation,
// so CUTOFF is bounded by the ghost shell.
#include <array>
#include <cmath>
#include <cstdio>
#include <unordered_map>
#include <vector>

#include "comm/comm.h"
#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/utils.h"
#include "domain/domain.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeCoordAtom : public Compute {
 public:
  ComputeCoordAtom(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID coord/atom CUTOFF [mix yes|no] [type ranges ...]";
    if (args.size() < 4) throw InputError("compute " + id + " coord/atom: missing cutoff; usage: " + usage);
    cutoff_ = parse_double(args[3], "compute " + id + " coord/atom cutoff");
    if (!(cutoff_ > 0.0))
      throw InputError("compute " + id + " coord/atom: the cutoff must be > 0; usage: " + usage);
    const int ntypes = engine.particles->ntypes;
    for (std::size_t k = 4; k < args.size(); ++k) {
      if (args[k] == "mix") {
        if (k + 1 >= args.size()) throw InputError("compute " + id + " coord/atom: mix needs yes or no");
        mix_ = parse_bool(args[++k], "compute " + id + " coord/atom mix");
      } else {
        int lo = 0, hi = 0;
        parse_type_range(args[k], ntypes, lo, hi);
        ranges_.push_back({lo, hi});
      }
    }
    if (mix_ && ranges_.size() > 1)
      throw InputError("compute " + id +
                       " coord/atom: mix yes counts one number; give no type ranges with it");
    if (ranges_.empty()) ranges_.push_back({1, ntypes});
    peratom_flag = true;
    peratom_cols = ranges_.size() == 1 ? 0 : static_cast<int>(ranges_.size());
  }

  void compute_peratom() override {
    const Particles& p = *engine_.particles;
    const double reach = engine_.comm->cutghost - engine_.neighbor->skin;
    const auto& per = engine_.domain->periodic;
    if ((engine_.nprocs > 1 || per[0] || per[1] || per[2]) && cutoff_ > reach) {
      char msg[200];
      std::snprintf(msg, sizeof msg, "cutoff %g is longer than the ghost shell allows (%g)", cutoff_, reach);
      throw InputError("compute " + id + " coord/atom: " + msg +
                       "; widen the shell with comm_modify cutoff (cutoff + skin)");
    }
    const int ncol = static_cast<int>(ranges_.size());
    std::vector<std::vector<double>> count(ncol,
                                           std::vector<double>(static_cast<std::size_t>(p.nlocal), 0.0));
    // cells of side >= cutoff over every particle this rank holds
    const int n = p.size();
    const double inv = 1.0 / cutoff_;
    auto cell_of = [&](const Vec3& x) {
      return std::array<long long, 3>{static_cast<long long>(std::floor(x[0] * inv)),
                                      static_cast<long long>(std::floor(x[1] * inv)),
                                      static_cast<long long>(std::floor(x[2] * inv))};
    };
    auto key = [](long long a, long long b, long long c) {
      return (a * 73856093LL) ^ (b * 19349663LL) ^ (c * 83492791LL);
    };
    std::unordered_map<long long, std::vector<int>> cells;
    for (int j = 0; j < n; ++j) {
      const auto c = cell_of(p.x[j]);
      cells[key(c[0], c[1], c[2])].push_back(j);
    }
    const double cut2 = cutoff_ * cutoff_;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const auto c = cell_of(p.x[i]);
      for (long long a = c[0] - 1; a <= c[0] + 1; ++a)
        for (long long b = c[1] - 1; b <= c[1] + 1; ++b)
          for (long long d = c[2] - 1; d <= c[2] + 1; ++d) {
            auto it = cells.find(key(a, b, d));
            if (it == cells.end()) continue;
            for (int j : it->second) {
              if (j == i || (p.x[j] - p.x[i]).squaredNorm() >= cut2) continue;
              const auto cj = cell_of(p.x[j]);  // the hash may mix cells: count j from its own cell only
              if (cj[0] != a || cj[1] != b || cj[2] != d) continue;
              if (mix_ && p.type[j] == p.type[i]) continue;
              for (int col = 0; col < ncol; ++col)
                if (p.type[j] >= ranges_[col].first && p.type[j] <= ranges_[col].second) count[col][i] += 1.0;
            }
          }
    }
    if (peratom_cols == 0) {
      vector_atom = std::move(count[0]);
    } else {
      array_atom = std::move(count);
    }
  }

 private:
  double cutoff_ = 0.0;
  bool mix_ = false;
  std::vector<std::pair<int, int>> ranges_;
};

}  // namespace

GRANARY_COMPUTE_STYLE("coord/atom", ComputeCoordAtom);

}  // namespace granary
