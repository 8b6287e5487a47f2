#include "comm/balance.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "neighbor/contact_history.h"
#include "neighbor/neighbor.h"
#include "core/force.h"
#include "particles/particles.h"

namespace granary {

ShiftSettings parse_shift(const Args& args, std::size_t first, const std::string& what) {
  if (args.size() < first + 3) {
    throw InputError(what + " shift needs DIMSTR NITER STOPTHRESH (e.g. shift z 20 1.05)");
  }
  ShiftSettings s;
  s.dims = args[first];
  for (std::size_t k = 0; k < s.dims.size(); ++k) {
    const char c = s.dims[k];
    if (c != 'x' && c != 'y' && c != 'z') {
      throw InputError(what + " shift: dimension string '" + s.dims +
                       "' may only contain the letters x, y and z");
    }
    if (s.dims.find(c) != k) {
      throw InputError(what + " shift: dimension string '" + s.dims + "' names " + std::string(1, c) +
                       " twice");
    }
  }
  if (s.dims.empty()) throw InputError(what + " shift needs a dimension string such as z or xz");
  const long long niter = parse_int(args[first + 1], what + " shift NITER");
  if (niter < 1 || niter > 1000) throw InputError(what + " shift NITER must be between 1 and 1000");
  s.niter = static_cast<int>(niter);
  s.stopthresh = parse_double(args[first + 2], what + " shift STOPTHRESH");
  if (!(s.stopthresh >= 1.0)) {
    throw InputError(what +
                     " shift STOPTHRESH must be >= 1.0 (the imbalance factor, largest over average "
                     "particle count per rank, is never below 1)");
  }
  return s;
}

WeightSettings parse_weight(const Args& args, std::size_t first, const std::string& what) {
  WeightSettings out;
  std::size_t k = first;
  while (k < args.size()) {
    const std::string& w = args[k];
    if (w == "weight") {
      if (k + 2 >= args.size() || (args[k + 1] != "time" && args[k + 1] != "neigh")) {
        throw InputError(what +
                         " weight: expected 'weight time FACTOR' (the measured cost per particle of each "
                         "rank) or 'weight neigh FACTOR' (each particle's neighbour count)");
      }
      out.kind = args[k + 1] == "time" ? WeightSettings::kTime : WeightSettings::kNeigh;
      out.factor = parse_double(args[k + 2], what + " weight " + args[k + 1] + " FACTOR");
      if (!(out.factor > 0.0 && out.factor <= 1.0))
        throw InputError(what + " weight " + args[k + 1] + " FACTOR must be in (0, 1]");
      k += 3;
    } else if (w == "out") {
      throw InputError(what + " keyword 'out' is not supported");
    } else {
      throw InputError("unknown " + what + " keyword '" + w +
                       "'; expected weight time FACTOR or weight neigh FACTOR");
    }
  }
  return out;
}

Balancer::Balancer(Engine& engine) : engine_(engine) {}

void Balancer::set_time_weight(double factor, double seconds) {
  const Particles& p = *engine_.particles;
  double mine[2] = {std::max(seconds, 0.0), static_cast<double>(p.nlocal)}, all[2] = {0.0, 0.0};
  MPI_Allreduce(mine, all, 2, MPI_DOUBLE, MPI_SUM, engine_.world);
  weight_ = 1.0;
  if (!(all[0] > 0.0) || !(all[1] > 0.0) || p.nlocal == 0) return;
  const double mean = all[0] / all[1];  // seconds per particle over all ranks
  const double here = mine[0] / mine[1];
  weight_ = (1.0 - factor) + factor * here / mean;
}

void Balancer::set_neigh_weight(double factor) {
  const Particles& p = *engine_.particles;
  const Neighbor& nb = *engine_.neighbor;
  const int n = p.nlocal;
  // list entries per owned particle, both ends of each pair
  // The list covers the particles owned at its build; particles appended
  // since (insertion) come after them. With fewer particles than the list
  // (deleted since) the indices no longer match and every weight is 1.
  std::vector<double> count(n, 0.0);
  const int built = static_cast<int>(nb.offset.size()) - 1;
  const int covered = built >= 0 && built <= n ? built : 0;
  for (int i = 0; i < covered; ++i) {
    for (int k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      count[i] += 1.0;
      const int j = nb.neigh[k];
      if (j < covered) count[j] += 1.0;  // an owned partner (ghosts were indexed from `built` on)
    }
  }
  double mine[2] = {0.0, static_cast<double>(std::max(covered, 0))}, all[2] = {0.0, 0.0};
  for (int i = 0; i < covered; ++i)
    mine[0] += count[i];
  MPI_Allreduce(mine, all, 2, MPI_DOUBLE, MPI_SUM, engine_.world);
  weights_.assign(n, 1.0);
  if (!(all[0] > 0.0) || !(all[1] > 0.0)) return;
  const double mean = all[0] / all[1];
  for (int i = 0; i < covered; ++i)
    weights_[i] = (1.0 - factor) + factor * count[i] / mean;
}

std::vector<double> Balancer::cell_loads(const std::array<std::vector<double>, 3>& cuts) const {
  const Comm& c = *engine_.comm;
  const Particles& p = *engine_.particles;
  std::vector<double> local(static_cast<std::size_t>(engine_.nprocs), 0.0), all(local.size(), 0.0);
  for (int i = 0; i < p.nlocal; ++i) {
    int loc[3];
    for (int d = 0; d < 3; ++d)
      loc[d] = c.slab_of(d, p.x[i][d], cuts[d]);
    local[c.rank_at(loc[0], loc[1], loc[2])] += weights_.empty() ? weight_ : weights_[i];
  }
  MPI_Allreduce(local.data(), all.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, engine_.world);
  return all;
}

std::vector<double> Balancer::rank_loads() const {
  const Particles& p = *engine_.particles;
  double mine = 0.0;
  for (int i = 0; i < p.nlocal; ++i)
    mine += weights_.empty() ? weight_ : weights_[i];
  std::vector<double> all(static_cast<std::size_t>(engine_.nprocs), 0.0);
  MPI_Allgather(&mine, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, engine_.world);
  return all;
}

BalanceResult Balancer::rcb(double thresh) {
  Engine& e = engine_;
  Comm& c = *e.comm;
  const Domain& dom = *e.domain;
  const Particles& p = *e.particles;
  const int nprocs = e.nprocs, n = p.nlocal;
  BalanceResult r;
  std::vector<double> loads = rank_loads();
  r.imbalance_before = imbalance(loads, &r.max_before);
  r.imbalance_after = r.imbalance_before;
  r.max_after = r.max_before;
  if (!(r.imbalance_before > thresh)) return r;
  r.balanced = true;
  auto weight = [&](int i) { return weights_.empty() ? weight_ : weights_[i]; };
  const int ndims = dom.dimension == 2 ? 2 : 3;

  struct Part {
    int r0, r1;                    // ranks r0 .. r1-1
    std::array<double, 3> lo, hi;  // fractions of the box
  };
  std::vector<RcbNode> tree(1);
  std::vector<Part> parts{{0, nprocs, {{0.0, 0.0, 0.0}}, {{1.0, 1.0, 1.0}}}};
  if (nprocs == 1) tree[0].rank = 0;
  std::vector<int> node_of(static_cast<std::size_t>(n), 0);
  std::vector<int> active;
  if (nprocs > 1) active.push_back(0);
  const double inf = std::numeric_limits<double>::infinity();
  while (!active.empty()) {
    const int na = static_cast<int>(active.size());
    std::vector<int> slot(tree.size(), -1);
    for (int k = 0; k < na; ++k)
      slot[active[k]] = k;
    // weight and extent (minimum, and maximum as a negated minimum) of the particles of each part
    std::vector<double> sum(na, 0.0), sum_all(na, 0.0), ext(6 * static_cast<std::size_t>(na), inf),
        ext_all(ext.size(), inf);
    for (int i = 0; i < n; ++i) {
      const int k = slot[node_of[i]];
      if (k < 0) continue;
      sum[k] += weight(i);
      for (int d = 0; d < 3; ++d) {
        ext[6 * k + d] = std::min(ext[6 * k + d], p.x[i][d]);
        ext[6 * k + 3 + d] = std::min(ext[6 * k + 3 + d], -p.x[i][d]);
      }
    }
    MPI_Allreduce(sum.data(), sum_all.data(), na, MPI_DOUBLE, MPI_SUM, e.world);
    MPI_Allreduce(ext.data(), ext_all.data(), 6 * na, MPI_DOUBLE, MPI_MIN, e.world);
    std::vector<int> dim(na, 0);
    std::vector<double> target(na), lo(na), hi(na), below_lo(na, 0.0), below_hi(na), cut(na);
    for (int k = 0; k < na; ++k) {
      const Part& part = parts[active[k]];
      // the dimension of the largest spread of the particles (of the part's box without particles)
      double best = -1.0;
      for (int d = 0; d < ndims; ++d) {
        const double spread = ext_all[6 * k + d] < inf ? -ext_all[6 * k + 3 + d] - ext_all[6 * k + d]
                                                       : (part.hi[d] - part.lo[d]) * dom.prd[d];
        if (spread > best) {
          best = spread;
          dim[k] = d;
        }
      }
      const int nlo = (part.r1 - part.r0) / 2;
      target[k] = sum_all[k] * nlo / (part.r1 - part.r0);
      lo[k] = part.lo[dim[k]];
      hi[k] = part.hi[dim[k]];
      below_hi[k] = sum_all[k];
    }
    // bisection of all parts together: below(lo) < target <= below(hi)
    std::vector<double> below(na), below_all(na);
    for (int it = 0; it < 64; ++it) {
      bool open = false;
      for (int k = 0; k < na; ++k) {
        cut[k] = 0.5 * (lo[k] + hi[k]);
        open = open || (cut[k] > lo[k] && cut[k] < hi[k] && below_hi[k] != target[k]);
      }
      if (!open) break;
      std::fill(below.begin(), below.end(), 0.0);
      std::vector<double> at(na);
      for (int k = 0; k < na; ++k)
        at[k] = c.frac_coord(dim[k], cut[k]);
      for (int i = 0; i < n; ++i) {
        const int k = slot[node_of[i]];
        if (k >= 0 && p.x[i][dim[k]] < at[k]) below[k] += weight(i);
      }
      MPI_Allreduce(below.data(), below_all.data(), na, MPI_DOUBLE, MPI_SUM, e.world);
      ++r.iterations;
      for (int k = 0; k < na; ++k) {
        if (!(cut[k] > lo[k] && cut[k] < hi[k]) || below_hi[k] == target[k]) continue;
        if (below_all[k] < target[k]) {
          lo[k] = cut[k];
          below_lo[k] = below_all[k];
        } else {
          hi[k] = cut[k];
          below_hi[k] = below_all[k];
        }
      }
    }
    // the nearer of the two brackets (a part without particles: in proportion
    // to its ranks); rank 0's choice for everybody
    for (int k = 0; k < na; ++k) {
      const Part& part = parts[active[k]];
      if (sum_all[k] > 0.0) {
        cut[k] = target[k] - below_lo[k] < below_hi[k] - target[k] ? lo[k] : hi[k];
      } else {
        const double share = static_cast<double>((part.r1 - part.r0) / 2) / (part.r1 - part.r0);
        cut[k] = part.lo[dim[k]] + share * (part.hi[dim[k]] - part.lo[dim[k]]);
      }
    }
    MPI_Bcast(cut.data(), na, MPI_DOUBLE, 0, e.world);
    MPI_Bcast(dim.data(), na, MPI_INT, 0, e.world);
    std::vector<int> next;
    for (int k = 0; k < na; ++k) {
      const int id = active[k];
      const Part part = parts[id];
      const int nlo = (part.r1 - part.r0) / 2;
      Part below_part = part, above_part = part;
      below_part.r1 = part.r0 + nlo;
      below_part.hi[dim[k]] = cut[k];
      above_part.r0 = part.r0 + nlo;
      above_part.lo[dim[k]] = cut[k];
      const int a = static_cast<int>(tree.size());
      tree[id].dim = dim[k];
      tree[id].cut = cut[k];
      tree[id].lo = a;
      tree[id].hi = a + 1;
      for (const Part& child : {below_part, above_part}) {
        RcbNode node;
        if (child.r1 - child.r0 == 1) node.rank = child.r0;
        const int cid = static_cast<int>(tree.size());
        tree.push_back(node);
        parts.push_back(child);
        if (child.r1 - child.r0 > 1) next.push_back(cid);
      }
    }
    for (int i = 0; i < n; ++i) {
      const int k = slot[node_of[i]];
      if (k < 0) continue;
      const RcbNode& node = tree[active[k]];
      node_of[i] = p.x[i][node.dim] >= c.frac_coord(node.dim, node.cut) ? node.hi : node.lo;
    }
    active = std::move(next);
  }
  // loads of the new boxes
  std::vector<double> mine(static_cast<std::size_t>(nprocs), 0.0);
  for (int i = 0; i < n; ++i)
    mine[tree[node_of[i]].rank] += weight(i);
  MPI_Allreduce(mine.data(), loads.data(), nprocs, MPI_DOUBLE, MPI_SUM, e.world);
  r.imbalance_after = imbalance(loads, &r.max_after);
  c.set_rcb(std::move(tree));
  return r;
}

double Balancer::imbalance(const std::vector<double>& loads, double* maxload) {
  double total = 0.0, most = 0.0;
  for (double l : loads) {
    total += l;
    most = std::max(most, l);
  }
  if (maxload) *maxload = most;
  if (total <= 0.0 || loads.empty()) return 1.0;
  return most / (total / static_cast<double>(loads.size()));
}

double Balancer::min_width() const {
  Engine& e = engine_;
  // During a run the ghost cutoff is fixed; between runs it is what the next
  // run's setup will compute from the current particles.
  if (!e.update->running) e.neighbor->init();
  return std::max(e.neighbor->cutneighmax, e.comm->cutghost_user);
}

BalanceResult Balancer::shift(double thresh, const ShiftSettings& settings, double minwidth) {
  Comm& c = *engine_.comm;
  const Domain& dom = *engine_.domain;
  BalanceResult r;
  std::array<std::vector<double>, 3> cuts = c.split;
  std::vector<double> loads = cell_loads(cuts);
  r.imbalance_before = imbalance(loads, &r.max_before);
  r.imbalance_after = r.imbalance_before;
  r.max_after = r.max_before;
  if (!(r.imbalance_before > thresh)) return r;
  r.balanced = true;
  double best = r.imbalance_before;
  double total = 0.0;
  for (double l : loads)
    total += l;

  for (char letter : settings.dims) {
    if (best <= settings.stopthresh) break;
    const int d = letter - 'x';
    const int np = c.procgrid[d];
    if (np == 1) continue;
    // Smallest slab width as a fraction of the box, with a margin so that
    // the width computed from coordinates is not below the cutoff by round-off.
    const double w = minwidth / dom.prd[d] * (1.0 + 1e-9) + 1e-15;
    if (w * np > 1.0) continue;  // cannot be respected; Comm::setup reports it
    // Bisection brackets of every interior cut k (fractions of the box):
    // lo[k] has fewer than k/P of the particles below it, hi[k] at least
    // that many. Every evaluated set of cuts narrows the brackets of all k.
    std::vector<double> lo(np + 1, 0.0), hi(np + 1, 1.0), target(np + 1, 0.0);
    for (int k = 1; k < np; ++k)
      target[k] = total * k / np;
    std::vector<double> cur = cuts[d];
    std::vector<double> cur_loads = loads;
    for (int it = 0; it < settings.niter && best > settings.stopthresh; ++it) {
      // particles below each evaluated cut, from the counts of the grid cells
      std::vector<double> below(np + 1, 0.0);
      for (int rank = 0; rank < engine_.nprocs; ++rank) {
        const int loc[3] = {rank % c.procgrid[0], (rank / c.procgrid[0]) % c.procgrid[1],
                            rank / (c.procgrid[0] * c.procgrid[1])};
        below[loc[d] + 1] += cur_loads[rank];
      }
      for (int j = 1; j <= np; ++j)
        below[j] += below[j - 1];
      std::vector<double> trial(np + 1);
      for (int k = 1; k < np; ++k) {
        for (int j = 1; j < np; ++j) {
          if (below[j] < target[k])
            lo[k] = std::max(lo[k], cur[j]);
          else
            hi[k] = std::min(hi[k], cur[j]);
        }
        trial[k] = 0.5 * (lo[k] + hi[k]);
      }
      trial[0] = 0.0;
      trial[np] = 1.0;
      // ordered and at least w apart (feasible since w * np <= 1)
      for (int k = 1; k < np; ++k)
        trial[k] = std::max(trial[k], trial[k - 1] + w);
      for (int k = np - 1; k >= 1; --k)
        trial[k] = std::min(trial[k], trial[k + 1] - w);
      std::array<std::vector<double>, 3> trial_cuts = cuts;
      trial_cuts[d] = trial;
      std::vector<double> trial_loads = cell_loads(trial_cuts);
      const double imb = imbalance(trial_loads);
      ++r.iterations;
      cur = trial;
      cur_loads = trial_loads;
      if (imb < best) {
        best = imb;
        cuts = trial_cuts;
        loads = trial_loads;
      }
    }
  }
  c.split = cuts;
  r.imbalance_after = imbalance(loads, &r.max_after);
  return r;
}

void Balancer::migrate() {
  Engine& e = engine_;
  ContactHistory* history = e.force->contact_history();
  e.particles->clear_ghosts();
  e.comm->setup(min_width());
  e.comm->exchange(history);
  int local = e.comm->nlost, total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_INT, MPI_SUM, e.world);
  if (total > 0) {
    e.particles->natoms -= total;
    e.logger->warning(std::to_string(total) +
                      " particle(s) outside a fixed boundary were removed by balance");
  }
  e.particles->map_clear();
  // ghosts and neighbour lists are rebuilt by the next run's setup
  e.update->first_run = true;
}

std::string Balancer::summary(const BalanceResult& r) const {
  const Comm& c = *engine_.comm;
  std::string out = "Balancing ...\n";
  char line[256];
  std::snprintf(line, sizeof line, "  iteration count = %d\n", r.iterations);
  out += line;
  std::snprintf(line, sizeof line, "  initial/final maximal load/proc = %.15g %.15g\n", r.max_before,
                r.max_after);
  out += line;
  std::snprintf(line, sizeof line, "  initial/final imbalance factor  = %.6g %.6g\n", r.imbalance_before,
                r.imbalance_after);
  out += line;
  if (c.tiled() && !c.rcb_tree().empty()) {
    std::snprintf(line, sizeof line, "  rcb: %d boxes in %d cuts\n", engine_.nprocs, engine_.nprocs - 1);
    out += line;
    return out;
  }
  for (int d = 0; d < 3; ++d) {
    out += std::string("  ") + "xyz"[d] + " cuts:";
    for (int k = 0; k <= c.procgrid[d]; ++k) {
      std::snprintf(line, sizeof line, " %.6g", k == c.procgrid[d] ? 1.0 : c.split[d][k]);
      out += line;
    }
    out += "\n";
  }
  return out;
}

// balance THRESH shift DIMSTR NITER STOPTHRESH
// balance THRESH x|y|z uniform|CUTS... [x|y|z ...]
// balance THRESH rcb (comm_style tiled)
void cmd_balance(Engine& e, const Args& a) {
  const std::string usage =
      "balance THRESH shift DIMSTR NITER STOPTHRESH [weight time|neigh FACTOR], balance THRESH x|y|z "
      "uniform|C1 ..., or balance THRESH rcb [weight time|neigh FACTOR] (e.g. balance 1.1 shift z 20 1.05)";
  if (!e.domain->box_exist)
    throw InputError("balance needs a simulation box: use create_box or read_restart first");
  if (a.size() < 2) throw InputError("balance: too few arguments; usage: " + usage);
  const double thresh = parse_double(a[0], "balance THRESH");
  if (!(thresh > 0.0)) throw InputError("balance THRESH must be positive (below 1.0 the cuts always move)");
  Comm& c = *e.comm;
  Balancer bal(e);
  // Arguments are checked before anything changes. Cuts are fractions of
  // the box the next run will use (shrink-wrapped faces reset first).
  auto prepare = [&]() {
    e.domain->reset_box();
    return bal.min_width();
  };
  BalanceResult r;
  auto weigh = [&](const WeightSettings& weight) {
    if (weight.kind == WeightSettings::kNeigh &&
        e.neighbor->offset.size() != static_cast<std::size_t>(e.particles->nlocal) + 1) {
      throw InputError(
          "balance weight neigh needs the neighbour lists of the current particles; they are built by a "
          "run (use 'run 0' after creating or deleting particles)");
    }
    // cost measured over the last run: its pair and neighbour time on this rank
    if (weight.kind == WeightSettings::kTime)
      bal.set_time_weight(weight.factor, e.update->timers[Update::kPair] + e.update->timers[Update::kNeigh]);
    if (weight.kind == WeightSettings::kNeigh) bal.set_neigh_weight(weight.factor);
  };
  if (a[1] == "rcb") {
    const WeightSettings weight = parse_weight(a, 2, "balance");
    if (!c.tiled()) {
      throw InputError(
          "balance rcb needs comm_style tiled (its boxes are not a processor grid); put 'comm_style tiled' "
          "before the balance command");
    }
    prepare();
    weigh(weight);
    r = bal.rcb(thresh);
  } else if (a[1] == "shift") {
    const ShiftSettings s = parse_shift(a, 2, "balance");
    const WeightSettings weight = parse_weight(a, 5, "balance");
    const double minwidth = prepare();
    weigh(weight);
    if (c.tiled()) c.clear_rcb();  // a grid style starts from the grid
    r = bal.shift(thresh, s, minwidth);
  } else if (a[1] == "x" || a[1] == "y" || a[1] == "z") {
    // explicit cuts per dimension, LAMMPS' x/y/z styles
    std::array<std::vector<double>, 3> cuts = c.split;
    bool given[3] = {false, false, false};
    std::size_t k = 1;
    while (k < a.size()) {
      const std::string& w = a[k];
      if (w == "weight") throw InputError("balance weight needs the shift style");
      if (w.size() != 1 || (w[0] != 'x' && w[0] != 'y' && w[0] != 'z'))
        throw InputError("balance: expected x, y or z instead of '" + w + "'; usage: " + usage);
      const int d = w[0] - 'x';
      if (given[d]) throw InputError("balance: dimension " + w + " given twice");
      given[d] = true;
      const int np = c.procgrid[d];
      if (k + 1 < a.size() && a[k + 1] == "uniform") {
        for (int j = 0; j <= np; ++j)
          cuts[d][j] = static_cast<double>(j) / np;
        k += 2;
        continue;
      }
      if (k + static_cast<std::size_t>(np) > a.size()) {
        throw InputError("balance " + w + " needs 'uniform' or " + std::to_string(np - 1) +
                         " ascending fractions between 0 and 1 (" + std::to_string(np) + " ranks along " + w +
                         ")");
      }
      cuts[d][0] = 0.0;
      cuts[d][np] = 1.0;
      for (int j = 1; j < np; ++j) {
        cuts[d][j] = parse_double(a[k + j], "balance " + w + " cut");
        if (!(cuts[d][j] > cuts[d][j - 1]) || !(cuts[d][j] < 1.0))
          throw InputError("balance " + w + " cuts must ascend strictly between 0 and 1");
      }
      k += np;
    }
    const double minwidth = prepare();
    if (c.tiled()) c.clear_rcb();
    const std::vector<double> before = bal.cell_loads(c.split);
    r.imbalance_before = Balancer::imbalance(before, &r.max_before);
    r.imbalance_after = r.imbalance_before;
    r.max_after = r.max_before;
    if (r.imbalance_before > thresh) {
      c.check_widths(cuts, minwidth, "choose cuts that leave every subdomain at least that wide");
      c.split = cuts;
      r.balanced = true;
      r.imbalance_after = Balancer::imbalance(bal.cell_loads(cuts), &r.max_after);
    }
  } else {
    throw InputError("unknown balance style '" + a[1] + "'; usage: " + usage);
  }
  if (r.balanced) bal.migrate();
  e.logger->print(bal.summary(r));
}
GRANARY_COMMAND("balance", cmd_balance);

}  // namespace granary
