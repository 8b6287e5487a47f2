// fix ID group adapt N atom diameter v_name [scale no|yes] [reset no]
// (LAMMPS/LIGGGHTS): sets the diameter of every particle of the group to the
// value of variable `name` (equal-style: one value for all; atom-style: one
// per particle) at the start of every run and every N steps of it (N = 0: at
// the start only); with scale yes the value multiplies the diameter the
// particle had when the run started. The mass follows at the particle's
// density. Changed radii and masses are sent to ghost particles at once, and
// the neighbour lists are rebuilt at the next step so that the grown
// particles' contacts are found.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "fix/fix.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixAdapt : public Fix {
 public:
  FixAdapt(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage = "fix ID group adapt N atom diameter v_name [scale no|yes] [reset no]";
    require_args(args, 7, 11, usage);
    const long long n = parse_int(args[3], "fix " + id + " adapt N");
    if (n < 0) throw InputError("fix " + id + " adapt: N must be >= 0, got " + args[3]);
    every_ = static_cast<int>(n);
    std::size_t k = 4;
    if (args[k] == "pair")
      throw InputError("fix " + id +
                       " adapt: 'pair' is not supported (it changes parameters of pair styles such as soft; "
                       "the granular pair styles take their parameters from fix property/global)");
    if (args[k] != "atom")
      throw InputError("fix " + id + " adapt: expected the attribute 'atom', got '" + args[k] +
                       "'; usage: " + usage);
    if (args[k + 1] != "diameter")
      throw InputError("fix " + id + " adapt: atom attribute '" + args[k + 1] +
                       "' is not supported (only diameter: Granary's particles carry no charge)");
    const std::string& v = args[k + 2];
    if (v.rfind("v_", 0) != 0 || v.size() < 3)
      throw InputError("fix " + id + " adapt: the value must be a variable v_name, got '" + v + "'");
    variable_ = v.substr(2);
    for (k += 3; k < args.size(); k += 2) {
      if (k + 1 >= args.size()) throw InputError("fix " + id + " adapt: " + args[k] + " needs yes or no");
      const std::string& key = args[k];
      const std::string& val = args[k + 1];
      if (val != "yes" && val != "no")
        throw InputError("fix " + id + " adapt: " + key + " must be yes or no, got '" + val + "'");
      if (key == "scale") {
        scale_ = val == "yes";
      } else if (key == "reset") {
        if (val == "yes")
          throw InputError(
              "fix " + id +
              " adapt: reset yes is not supported; the diameters stay as the fix left them at the "
              "end of a run (reset no, the default)");
      } else {
        throw InputError("fix " + id + " adapt: unknown keyword '" + key +
                         "' (scale, reset); usage: " + usage);
      }
    }
  }

  unsigned hooks() const override { return PRE_FORCE; }

  void init() override {
    Variables& vars = engine_.input->variables();
    if (!vars.find(variable_))
      throw InputError("fix " + id + " adapt: variable '" + variable_ + "' does not exist");
    const std::string st = vars.style(variable_);
    atom_ = vars.is_atom(variable_);
    if (!atom_ && st != "equal")
      throw InputError("fix " + id + " adapt: variable '" + variable_ +
                       "' must be equal- or atom-style, not " + st);
  }

  void pre_force() override {
    const Update& u = *engine_.update;
    if (u.in_setup_forces) {
      // the start of a run: the original diameters (scale yes), then a change
      if (scale_) {
        const Particles& p = *engine_.particles;
        field_ = engine_.particles->add_field("adapt/" + id, 1, false, true);
        double* d = engine_.particles->extras[field_].data.data();
        for (int i = 0; i < p.nlocal; ++i)
          d[i] = 2.0 * p.radius[i];
      }
      change();
      return;
    }
    if (every_ > 0 && u.ntimestep % every_ == 0) change();
  }

  void unfixed() override {
    if (field_ >= 0) engine_.particles->release_field("adapt/" + id);
  }

 private:
  void change() {
    Particles& p = *engine_.particles;
    Variables& vars = engine_.input->variables();
    double value = 0.0;
    if (atom_) {
      vars.compute_atom(variable_, values_);
      values_.resize(p.nlocal, 0.0);
    } else {
      value = vars.compute_equal(variable_);
    }
    const double* orig = scale_ && field_ >= 0 ? p.extras[field_].data.data() : nullptr;
    // every new diameter is checked on every rank before any is set
    diameters_.assign(p.nlocal, 0.0);
    long long bad = 0, clump = 0;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      double d = atom_ ? values_[i] : value;
      if (scale_) d *= orig ? orig[i] : 2.0 * p.radius[i];
      if (!(d > 0.0) || !std::isfinite(d)) ++bad;
      if (p.body[i] >= 0) ++clump;
      diameters_[i] = d;
    }
    long long local[2] = {bad, clump}, all[2] = {0, 0};
    MPI_Allreduce(local, all, 2, MPI_LONG_LONG, MPI_SUM, engine_.world);
    if (all[1] > 0)
      throw RunError("fix " + id + " adapt: its group holds " + std::to_string(all[1]) +
                     " sphere(s) of clumps, whose mass and inertia the fix cannot change; use a group of "
                     "single spheres");
    if (all[0] > 0)
      throw RunError("fix " + id + " adapt: variable '" + variable_ + "' gives " + std::to_string(all[0]) +
                     " diameter(s) that are not positive at step " +
                     std::to_string(engine_.update->ntimestep) + "; no diameter was changed");
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      p.radius[i] = 0.5 * diameters_[i];
      if (p.density[i] > 0.0) p.rmass[i] = Particles::sphere_mass(p.radius[i], p.density[i]);
    }
    // ghosts carry radius and mass from their owner
    engine_.comm->forward_comm_field(p.radius, 1);
    engine_.comm->forward_comm_field(p.rmass, 1);
    // lists (and ghosts) again at the next step, with a cutoff that covers
    // the largest particle
    Neighbor& nb = *engine_.neighbor;
    const double rmax = p.max_radius(engine_.world);
    if (rmax > nb.rmax) {
      nb.rmax = rmax;
      nb.cutneighmax = nb.cutoff_for(nb.rmax);
    }
    nb.force_rebuild = true;
  }

  int every_ = 0;
  std::string variable_;
  bool atom_ = false;
  bool scale_ = false;
  int field_ = -1;
  std::vector<double> values_, diameters_;
};

}  // namespace

GRANARY_FIX_STYLE("adapt", FixAdapt);

}  // namespace granary
