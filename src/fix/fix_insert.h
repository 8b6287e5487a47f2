// Particle insertion: the machinery shared by fix insert/pack,
// insert/rate/region and insert/stream (FixInsert).
//
// How insertion works (identical on every rank, so it does not depend on the
// number of ranks):
// - At an insertion step every rank draws the same particles from the
//   distribution and the same candidate positions (and orientations) from the
//   fix's own generator, seeded by SEED.
// - With overlapcheck, every rank knows the existing particles near the
//   region (gathered from all ranks), the primitive walls (fix wall/gran) and
//   the particles placed so far; a candidate that overlaps any of them, or
//   (all_in yes) is not wholly inside the region, is rejected and retried up to
//   maxattempt times.
// - Ids continue from the largest id anywhere + 1, in placement order (a
//   multisphere particle takes consecutive ids for its spheres). Each rank
//   creates the spheres it owns (Comm::owner_of). For a multisphere template
//   every rank then calls the BodyRegistrar (fix multisphere) with the same
//   arguments, after all spheres of the batch were created.
//
// When it acts: insertion steps are steps of a run (the first one is the first
// step of the next run, or `start`). The schedule is kept in restart files, and
// when the step counter is changed (reset_timestep) the schedule moves with it:
// the number of steps to the next insertion stays the same. In post_integrate of such a step the fix
// sets Neighbor::force_rebuild, so the step reneighbours; in pre_exchange of
// that step the particles are added. At that point ghosts and the neighbour
// list of the previous build still exist (the contact history is saved from
// the list right after pre_exchange), so the new owned particles are put in
// front of the ghosts: the ghosts move up by the number added, the list's
// ghost indices are shifted with them and the new particles get empty list
// rows. Migration, ghosts and the new list then follow in the same step, and
// the neighbour cutoff is raised when the new spheres are larger than any
// before.
#pragma once

#include <Eigen/Geometry>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "fix/fix.h"
#include "fix/fix_particle_template.h"

namespace granary {

class Region;
class FixParticleDistributionDiscrete;

class FixInsert : public Fix {
 public:
  /// `style_keywords` maps the style's own keywords to their number of values;
  /// their values are left in style_values_ for the derived constructor.
  /// `needs_region`: whether the `region` keyword is required (styles that
  /// build their own insertion volume, like insert/stream, override region()).
  FixInsert(Engine& engine, const Args& args, const std::map<std::string, int>& style_keywords,
            const std::string& usage, bool needs_region = true);

  unsigned hooks() const override { return POST_INTEGRATE | PRE_EXCHANGE; }
  void init() override;
  void post_integrate() override;
  void pre_exchange() override;

  /// f_ID[1]: particles inserted so far, f_ID[2]: their mass [kg].
  double compute_vector(int i) override;
  void pack_restart(std::string& out) const override;
  void unpack_restart(const std::string& in) override;

  /// Step of the next insertion (-1 when done), on the current step counter.
  std::int64_t next_step() const;
  long long inserted() const { return ninserted_; }
  double mass_inserted() const { return mass_inserted_; }

  /// Volume of the region inside the box (exact where the region knows it,
  /// else Monte Carlo with ntry_mc points), computed at init.
  double region_volume() const { return region_volume_; }

  /// Outcome of one insertion.
  struct Result {
    long long requested = 0, placed = 0;
    double mass = 0.0, volume = 0.0;
  };

 protected:
  /// Called at each insertion step: how many particles to insert now.
  virtual long long count_to_insert() = 0;
  /// Called after an insertion with its outcome (report, bookkeeping).
  virtual void inserted_batch(const Result& r) = 0;
  /// Whether insertion is complete after this step (once, or a target reached).
  virtual bool done_after_insertion() const { return insert_every_ == 0; }

  /// Place up to n particles drawn from the distribution and create them.
  Result insert(long long n);
  /// Number, mass and sphere volume of the particles whose centre lies in the
  /// region (collective). Multisphere particles count once in `number`.
  void count_in_region(double& number, double& mass, double& volume) const;
  /// Integer count from an expected value with stochastic rounding (same on every rank).
  long long round_stochastic(double x);
  std::string label() const { return "fix " + id + " (" + style + ")"; }

  FixParticleDistributionDiscrete& dist() const;
  /// The insertion volume: the region named by `region`, or one the style builds.
  virtual Region& region() const;
  /// Shift from a point drawn in the region to the particle's centre, for a
  /// particle of bounding radius r (insert/stream: away from the face by r).
  /// all_in tests the sphere at the unshifted point.
  virtual Vec3 candidate_shift(double /*r*/) const { return Vec3::Zero(); }

  std::map<std::string, Args> style_values_;
  std::string dist_id_, region_id_;
  /// set_property NAME value: scalar fix property/atom values of the inserted
  /// particles (names here, field indices found at init)
  std::vector<std::pair<std::string, double>> set_property_;
  std::vector<std::pair<int, double>> set_fields_;
  long long seed_ = 0;
  int maxattempt_ = 50;
  int insert_every_ = 0;     // 0: once
  std::int64_t start_ = -1;  // first insertion step (-1: the first step of the next run)
  bool overlapcheck_ = true;
  bool all_in_ = false;
  bool verbose_ = true;
  bool exact_ = true;  // random_distribute exact
  enum class VelStyle { Constant, Uniform, Gaussian } vel_style_ = VelStyle::Constant;
  Vec3 vel_{0, 0, 0}, vel_fluct_{0, 0, 0}, omega_{0, 0, 0};
  enum class Orientation { Random, Template, Constant } orientation_ = Orientation::Random;
  Eigen::Quaterniond quat_{1, 0, 0, 0};
  long long ntry_mc_ = 100000;

  std::int64_t next_step_ = -1;
  // the step counter when this fix last saw it: a different value at init
  // means reset_timestep moved it, and next_step_ moves by the same amount
  std::int64_t seen_step_ = 0;
  bool finished_ = false;
  long long ninserted_ = 0;
  double mass_inserted_ = 0.0;
  double region_volume_ = 0.0;
  std::mt19937_64 gen_;
  double uniform();
};

}  // namespace granary
