// fix ID group multisphere/break [multisphere keywords] trigger_threshold X
//     trigger_name f_ID|f_ID[k]|v_name [trigger_timeStep N]
// (LIGGGHTS syntax): fix multisphere whose clumps break. After every step
// from step N on, a clump one of whose sub-spheres has a trigger value above
// X (a per-atom value of a fix, or an atom-style variable) breaks at the next
// step: all its sub-spheres become free spheres, with the velocity and
// angular velocity they had in the clump (fix nve/sphere integrates them).
// See doc/fixes/multisphere_break.md.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "fix/fix_multisphere.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

namespace granary {

namespace {

bool is_trigger_key(const std::string& w) {
  return w == "trigger_threshold" || w == "trigger_timeStep" || w == "trigger_name" || w == "trigger_fixName";
}

// The arguments without the trigger keywords (for the multisphere part).
Args without_trigger(const Args& args) {
  Args out(args.begin(), args.begin() + std::min<std::size_t>(3, args.size()));
  for (std::size_t k = 3; k < args.size(); ++k) {
    if (is_trigger_key(args[k])) {
      if (k + 1 >= args.size())
        throw InputError("fix " + args[0] + " multisphere/break: '" + args[k] + "' needs a value");
      ++k;
    } else {
      out.push_back(args[k]);
    }
  }
  return out;
}

class FixMultisphereBreak : public FixMultisphere {
 public:
  FixMultisphereBreak(Engine& engine, const Args& args) : FixMultisphere(engine, without_trigger(args)) {
    const std::string where = "fix " + id + " multisphere/break";
    bool have_threshold = false;
    for (std::size_t k = 3; k + 1 < args.size(); ++k) {
      const std::string& w = args[k];
      if (!is_trigger_key(w)) continue;
      const std::string& v = args[++k];
      if (w == "trigger_threshold") {
        threshold_ = parse_double(v, where + " trigger_threshold");
        have_threshold = true;
      } else if (w == "trigger_timeStep") {
        start_step_ = parse_int(v, where + " trigger_timeStep");
        if (start_step_ < 0) throw InputError(where + ": trigger_timeStep must be >= 0");
      } else {  // trigger_name, trigger_fixName (a fix ID, with or without f_)
        name_ = w == "trigger_fixName" && v.rfind("f_", 0) != 0 ? "f_" + v : v;
      }
    }
    if (!have_threshold) throw InputError(where + ": missing 'trigger_threshold X'");
    if (name_.empty())
      throw InputError(where +
                       ": missing 'trigger_name f_ID|f_ID[k]|v_name' (the per-atom value compared with "
                       "the threshold)");
    if (name_.rfind("f_", 0) != 0 && name_.rfind("v_", 0) != 0)
      throw InputError(where + ": trigger_name '" + name_ +
                       "' must be a per-atom fix value (f_ID or f_ID[k]) or an atom-style variable (v_name)");
  }

  unsigned hooks() const override { return FixMultisphere::hooks() | END_OF_STEP | PRE_EXCHANGE; }

  void init() override {
    FixMultisphere::init();
    const std::string where = "fix " + id + " multisphere/break trigger_name " + name_;
    if (name_[0] == 'v') {
      auto& vars = engine_.input->variables();
      const std::string v = name_.substr(2);
      if (!vars.find(v))
        throw InputError(where + ": no variable '" + v + "'; define it with variable ... atom");
      if (!vars.is_atom(v)) throw InputError(where + ": variable '" + v + "' is not atom-style");
    } else {
      const std::string body = name_.substr(2);
      const auto open = body.find('[');
      fix_id_ = body.substr(0, open);
      column_ = 0;
      if (open != std::string::npos) {
        if (body.back() != ']') throw InputError(where + ": expected f_ID or f_ID[k]");
        column_ =
            static_cast<int>(parse_int(body.substr(open + 1, body.size() - open - 2), where + " column"));
        if (column_ < 1) throw InputError(where + ": the column must be >= 1");
      }
      engine_.modify->fix_or_error(fix_id_, where);
    }
  }

  // After the step: the clumps to break (on every rank the same list).
  void end_of_step() override {
    if (engine_.update->ntimestep < start_step_) return;
    Particles& p = *engine_.particles;
    if (name_[0] == 'v')
      engine_.input->variables().compute_atom(name_.substr(2), values_);
    else
      engine_.fix_peratom(fix_id_, column_, values_);
    std::vector<long long> mine;
    for (int i = 0; i < p.nlocal && i < static_cast<int>(values_.size()); ++i)
      if (p.body[i] >= 0 && values_[i] > threshold_) mine.push_back(static_cast<long long>(p.body[i]));
    std::sort(mine.begin(), mine.end());
    mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
    int n = static_cast<int>(mine.size()), nprocs = engine_.nprocs;
    std::vector<int> counts(nprocs), displs(nprocs, 0);
    MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, engine_.world);
    for (int r = 1; r < nprocs; ++r)
      displs[r] = displs[r - 1] + counts[r - 1];
    std::vector<long long> all(static_cast<std::size_t>(displs[nprocs - 1] + counts[nprocs - 1]));
    MPI_Allgatherv(mine.data(), n, MPI_LONG_LONG, all.data(), counts.data(), displs.data(), MPI_LONG_LONG,
                   engine_.world);
    if (all.empty()) return;
    pending_.insert(pending_.end(), all.begin(), all.end());
    engine_.neighbor->force_rebuild = true;  // the release happens at the next exchange
  }

  void pre_exchange() override {
    if (pending_.empty()) return;
    std::sort(pending_.begin(), pending_.end());
    pending_.erase(std::unique(pending_.begin(), pending_.end()), pending_.end());
    const long long n = release_bodies(pending_);
    pending_.clear();
    broken_ += n;
    if (n > 0)
      engine_.logger->print("fix multisphere/break " + id + ": " + std::to_string(n) +
                            " clump(s) broke at step " + std::to_string(engine_.update->ntimestep) + "\n");
  }

 private:
  double threshold_ = 0.0;
  long long start_step_ = 0;
  std::string name_, fix_id_;
  int column_ = 0;
  std::vector<double> values_;
  std::vector<tagint> pending_;  // bodies to break at the next exchange
  long long broken_ = 0;
};

}  // namespace

GRANARY_FIX_STYLE("multisphere/break", FixMultisphereBreak);

}  // namespace granary
