// Tracer particles (LIGGGHTS 3.8):
//
//   fix ID group property/atom/tracer region_mark REGION mark_step S
//       [marker_style dirac|heaviside] [check_mark_every N]
//
// marks particles of the group whose centre lies in REGION: with `dirac`
// (default) once, at the first step that is a multiple of N (default 10) and
// at or after step S; with `heaviside` at every such step from then on, so
// that every particle passing through the region is marked. f_ID is the
// per-atom marker (1 marked, 0 not); the global scalar is the number of
// particles marked since it was last read. compute nparticles/tracer/region
// counts marked particles in a region and may unmark them.
//
//   fix ID group property/atom/regiontracer/time [add_region REGION ...]
//       [check_region_every N]
//
// accumulates each particle's residence time: in the simulation (dt every
// step, for the particles of the group) and in each added region. Whether a
// particle is in a region is looked up every N steps (default 10; from the
// first such step of the run on) and holds until the next lookup; each step
// a particle is held in a region adds dt to its time there (as LIGGGHTS 3.8
// does, measured; its manual says dt*N per lookup). f_ID[1] is the time in
// the simulation, f_ID[1+k] the time in region k (f_ID alone without
// regions); the global vector holds their means over the group.
//
// Markers, times and the lookup state travel with the particles and are kept
// in restart files. Sub-spheres of clumps are treated each on its own (by its
// centre).
#include <mpi.h>

#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

// Register (or find, after read_restart) the per-particle field `name` with
// ncomp components; new particles start at zero.
int tracer_field(Engine& e, const std::string& fix_id, const std::string& name, int ncomp) {
  Particles& p = *e.particles;
  const int existing = p.find_field(name);
  if (existing >= 0 && !p.extras[existing].data.empty() && p.extras[existing].ncomp != ncomp) {
    throw InputError("fix " + fix_id + ": the restart file holds '" + name + "' with " +
                     std::to_string(p.extras[existing].ncomp) + " values per particle, this fix needs " +
                     std::to_string(ncomp) + " (give the fix the regions it had)");
  }
  try {
    const int f = p.add_field(name, ncomp, false, true);
    p.extras[f].restart = true;
    return f;
  } catch (const std::invalid_argument& err) {
    throw InputError("fix " + fix_id + ": " + err.what());
  }
}

long long positive_every(const std::string& word, const std::string& what) {
  const long long n = parse_int(word, what);
  if (n < 1) throw InputError(what + " must be a positive number of steps, got " + word);
  return n;
}

class FixPropertyAtomTracer : public Fix {
 public:
  FixPropertyAtomTracer(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group property/atom/tracer region_mark REGION mark_step S [marker_style dirac|heaviside] "
        "[check_mark_every N]";
    if (args.size() < 7 || args[3] != "region_mark" || args[5] != "mark_step")
      throw InputError("fix " + id + " property/atom/tracer: usage: " + usage);
    region_id_ = args[4];
    engine.domain->region_or_error(region_id_, "fix " + id);
    mark_step_ = parse_int(args[6], "fix " + id + " mark_step");
    if (mark_step_ < 0) throw InputError("fix " + id + " mark_step must be >= 0, got " + args[6]);
    for (std::size_t k = 7; k < args.size(); k += 2) {
      if (k + 1 >= args.size()) throw InputError("fix " + id + ": keyword '" + args[k] + "' needs a value");
      if (args[k] == "marker_style") {
        if (args[k + 1] != "dirac" && args[k + 1] != "heaviside")
          throw InputError("fix " + id + " marker_style must be dirac or heaviside, got '" + args[k + 1] +
                           "'");
        heaviside_ = args[k + 1] == "heaviside";
      } else if (args[k] == "check_mark_every") {
        nevery = static_cast<int>(positive_every(args[k + 1], "fix " + id + " check_mark_every"));
      } else {
        throw InputError("fix " + id + " property/atom/tracer: unknown keyword '" + args[k] +
                         "'; expected marker_style or check_mark_every");
      }
    }
    field_ = tracer_field(engine, id, "tracer_" + id, 1);
    peratom_flag = true;
    scalar_flag = true;
    restart_global = true;
  }

  unsigned hooks() const override { return END_OF_STEP; }

  void init() override { engine_.domain->region_or_error(region_id_, "fix " + id); }

  void end_of_step() override {
    if (engine_.update->ntimestep < mark_step_ || (done_ && !heaviside_)) return;
    const Region* region = engine_.domain->region_or_error(region_id_, "fix " + id);
    Particles& p = *engine_.particles;
    double* marker = p.extras[field_].data.data();
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit) || marker[i] != 0.0 || !region->match(p.x[i])) continue;
      marker[i] = 1.0;
      ++marked_;
    }
    done_ = true;
  }

  // Particles marked since the last call (collective).
  double compute_scalar() override {
    long long all = 0;
    MPI_Allreduce(&marked_, &all, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
    marked_ = 0;
    return static_cast<double>(all);
  }

  void peratom(int col, std::vector<double>& out) override {
    if (col > 1)
      throw InputError("fix " + id + " (property/atom/tracer) has one per-atom value: use f_" + id);
    const Particles& p = *engine_.particles;
    const double* marker = p.extras[field_].data.data();
    out.assign(marker, marker + p.nlocal);
  }

  void pack_restart(std::string& out) const override { out = done_ ? "1" : "0"; }
  void unpack_restart(const std::string& in) override { done_ = in == "1"; }
  void unfixed() override { engine_.particles->release_field("tracer_" + id); }

 private:
  std::string region_id_;
  long long mark_step_ = 0;
  bool heaviside_ = false;
  bool done_ = false;     // dirac: the marking has happened
  long long marked_ = 0;  // marked on this rank since the scalar was last read
  int field_ = -1;
};

class FixPropertyAtomRegionTracerTime : public Fix {
 public:
  FixPropertyAtomRegionTracerTime(Engine& engine, const Args& args) : Fix(engine, args) {
    for (std::size_t k = 3; k < args.size(); k += 2) {
      if (k + 1 >= args.size()) throw InputError("fix " + id + ": keyword '" + args[k] + "' needs a value");
      if (args[k] == "add_region") {
        engine.domain->region_or_error(args[k + 1], "fix " + id);
        regions_.push_back(args[k + 1]);
      } else if (args[k] == "check_region_every") {
        check_every_ = positive_every(args[k + 1], "fix " + id + " check_region_every");
      } else {
        throw InputError("fix " + id + " property/atom/regiontracer/time: unknown keyword '" + args[k] +
                         "'; expected add_region REGION or check_region_every N");
      }
    }
    const int nreg = static_cast<int>(regions_.size());
    // times (1 + regions), then the lookup flags of the regions
    field_ = tracer_field(engine, id, "residence_time_" + id, 1 + 2 * nreg);
    peratom_flag = true;
    peratom_cols = nreg > 0 ? 1 + nreg : 0;
    size_vector = 1 + nreg;
    restart_global = false;
  }

  unsigned hooks() const override { return END_OF_STEP; }

  void init() override {
    for (const auto& r : regions_)
      engine_.domain->region_or_error(r, "fix " + id);
  }

  void end_of_step() override {
    Particles& p = *engine_.particles;
    const int nreg = static_cast<int>(regions_.size()), nc = 1 + 2 * nreg;
    double* d = p.extras[field_].data.data();
    const double dt = engine_.update->dt;
    const bool lookup = engine_.update->ntimestep % check_every_ == 0;
    std::vector<const Region*> reg(nreg);
    for (int k = 0; k < nreg; ++k)
      reg[k] = engine_.domain->region_or_error(regions_[k], "fix " + id);
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      double* t = d + static_cast<std::size_t>(i) * nc;
      t[0] += dt;
      for (int k = 0; k < nreg; ++k) {
        double& inside = t[1 + nreg + k];
        if (lookup) inside = reg[k]->match(p.x[i]) ? 1.0 : 0.0;
        if (inside != 0.0) t[1 + k] += dt;
      }
    }
  }

  // Mean residence time over the group's particles (collective).
  double compute_vector(int i) override {
    const Particles& p = *engine_.particles;
    const int nreg = static_cast<int>(regions_.size()), nc = 1 + 2 * nreg;
    const double* d = p.extras[field_].data.data();
    double local[2] = {0.0, 0.0}, all[2] = {0.0, 0.0};
    for (int j = 0; j < p.nlocal; ++j) {
      if (!(p.mask[j] & groupbit)) continue;
      local[0] += d[static_cast<std::size_t>(j) * nc + i];
      local[1] += 1.0;
    }
    MPI_Allreduce(local, all, 2, MPI_DOUBLE, MPI_SUM, engine_.world);
    return all[1] > 0 ? all[0] / all[1] : 0.0;
  }

  void peratom(int col, std::vector<double>& out) override {
    const int nreg = static_cast<int>(regions_.size()), nc = 1 + 2 * nreg;
    if ((nreg == 0 && col > 1) || col > 1 + nreg) {
      throw InputError("fix " + id + " (property/atom/regiontracer/time) has " + std::to_string(1 + nreg) +
                       " per-atom value(s): use f_" + id +
                       (nreg ? "[1.." + std::to_string(1 + nreg) + "]" : ""));
    }
    const int c = col == 0 ? 0 : col - 1;
    const Particles& p = *engine_.particles;
    const double* d = p.extras[field_].data.data();
    out.resize(p.nlocal);
    for (int i = 0; i < p.nlocal; ++i)
      out[i] = d[static_cast<std::size_t>(i) * nc + c];
  }

  void unfixed() override { engine_.particles->release_field("residence_time_" + id); }

 private:
  std::vector<std::string> regions_;
  long long check_every_ = 10;
  int field_ = -1;
};

}  // namespace

GRANARY_FIX_STYLE("property/atom/tracer", FixPropertyAtomTracer);
GRANARY_FIX_STYLE("property/atom/regiontracer/time", FixPropertyAtomRegionTracerTime);

/// Marker field of a fix property/atom/tracer (for compute
/// nparticles/tracer/region); -1 unless `fix_id` names one.
int tracer_marker_field(Engine& e, const std::string& fix_id) {
  return e.particles->find_field("tracer_" + fix_id);
}

}  // namespace granary
