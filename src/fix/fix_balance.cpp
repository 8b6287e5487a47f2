// fix balance: dynamic load balancing by moving the cut planes of the
// processor grid (see src/comm/balance.h).
//   fix ID group balance NEVERY THRESH shift DIMSTR NITER STOPTHRESH [weight time|neigh FACTOR]
//   fix ID group balance NEVERY THRESH rcb [weight time|neigh FACTOR]   (comm_style tiled)
// At the setup of every run, and on every step that is a multiple of NEVERY
// (NEVERY = 0: setup only), the fix forces a reneighbouring and, in its
// pre_exchange hook (before particles migrate), moves the cuts when the
// imbalance factor exceeds THRESH. The exchange that follows in the same
// reneighbouring sends particles, with their contact history, to their new
// owners.
// f_ID = imbalance factor after the last balancing, f_ID[1] = largest
// particle count of a rank after it, f_ID[2] = iterations, f_ID[3] =
// imbalance factor before it.
#include "comm/balance.h"
#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "fix/fix.h"
#include "neighbor/neighbor.h"

namespace granary {

class FixBalance : public Fix {
 public:
  FixBalance(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group balance NEVERY THRESH shift DIMSTR NITER STOPTHRESH [weight time|neigh FACTOR] or fix "
        "ID group balance NEVERY THRESH rcb [weight time|neigh FACTOR]";
    if (args.size() < 6) throw InputError("fix balance: too few arguments; usage: " + usage);
    const long long n = parse_int(args[3], "fix balance NEVERY");
    if (n < 0) throw InputError("fix balance NEVERY must be >= 0 (0: balance only at the setup of each run)");
    every_ = n;
    thresh_ = parse_double(args[4], "fix balance THRESH");
    if (!(thresh_ > 0.0))
      throw InputError("fix balance THRESH must be positive (below 1.0 the cuts always move)");
    if (args[5] == "rcb") {
      rcb_ = true;
      weight_ = parse_weight(args, 6, "fix balance");
      require_tiled();
    } else if (args[5] == "shift") {
      settings_ = parse_shift(args, 6, "fix balance");
      weight_ = parse_weight(args, 9, "fix balance");
    } else {
      throw InputError("unknown fix balance style '" + args[5] + "'; usage: " + usage);
    }
    scalar_flag = true;
    size_vector = 3;
  }

  unsigned hooks() const override { return POST_INTEGRATE | PRE_EXCHANGE; }

  // Run setup reneighbours once: balance there.
  void init() override {
    if (rcb_) require_tiled();
    pending_ = true;
    setup_pending_ = true;
    mark_ = 0.0;
  }

  // On balancing steps, make this step reneighbour (decide() is collective
  // and the flag is set identically on every rank).
  void post_integrate() override {
    if (every_ > 0 && engine_.update->ntimestep % every_ == 0) {
      pending_ = true;
      engine_.neighbor->force_rebuild = true;
    }
  }

  void pre_exchange() override {
    if (!pending_) return;
    pending_ = false;
    const bool at_setup = setup_pending_;
    setup_pending_ = false;
    Balancer bal(engine_);
    // the shrink-wrapped box the exchange will use (reset_box is idempotent)
    engine_.domain->reset_box();
    // the neighbour lists of the last build still index the owned particles
    // here (particles added since count 1); at run setup they are the lists
    // of the previous run, if any
    if (weight_.kind == WeightSettings::kNeigh) bal.set_neigh_weight(weight_.factor);
    if (weight_.kind == WeightSettings::kTime && !at_setup) {
      // pair and neighbour time of this rank since the last balancing (the
      // timers restart with every run; at run setup nothing is measured yet,
      // so the particles count with weight 1 there)
      const Update& u = *engine_.update;
      const double now = u.timers[Update::kPair] + u.timers[Update::kNeigh];
      const double spent = now >= mark_ ? now - mark_ : now;
      bal.set_time_weight(weight_.factor, spent);
      mark_ = now;
    }
    if (rcb_) {
      last_ = bal.rcb(thresh_);
    } else {
      if (engine_.comm->tiled()) engine_.comm->clear_rcb();  // the shift style moves the grid's cuts
      last_ = bal.shift(thresh_, settings_, bal.min_width());
    }
    // subdomain bounds from the new cuts at once, for pre_exchange fixes
    // after this one (the reneighbouring sets them again, identically)
    if (last_.balanced) engine_.comm->setup(engine_.neighbor->cutneighmax);
  }

  double compute_scalar() override { return last_.imbalance_after; }
  double compute_vector(int i) override {
    if (i == 0) return last_.max_after;
    if (i == 1) return last_.iterations;
    return last_.imbalance_before;
  }

 private:
  void require_tiled() const {
    if (!engine_.comm->tiled()) {
      throw InputError("fix " + id +
                       " balance rcb needs comm_style tiled (its boxes are not a processor grid); put "
                       "'comm_style tiled' before the fix");
    }
  }
  bool rcb_ = false;
  long long every_ = 0;
  WeightSettings weight_;  // weight time|neigh FACTOR (none: particle count)
  double mark_ = 0.0;      // pair + neighbour time of this rank at the last balancing
  double thresh_ = 1.0;
  ShiftSettings settings_;
  BalanceResult last_;
  bool pending_ = false;
  bool setup_pending_ = false;  // the next balancing is the one at run setup
};

GRANARY_FIX_STYLE("balance", FixBalance);

}  // namespace granary
