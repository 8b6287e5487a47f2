// fix ID group gravity MAG vector X Y Z | spherical PHI THETA | chute ANGLE
//
// Adds m g to the force of every particle of the group after the pair forces.
// MAG [m/s^2] and the vector components may be equal-style variables (v_name),
// evaluated every step. The direction is normalised. The scalar output is the
// gravitational potential energy -sum m g.x of the group [J]; the vector
// (f_ID[1..3]) the acceleration of gravity [m/s^2].
#include <mpi.h>

#include <cmath>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group gravity MAG vector X Y Z | spherical PHI THETA | chute ANGLE  (MAG in m/s^2; "
    "angles in degrees)";

/// A number, or an equal-style variable v_name evaluated when asked.
class Value {
 public:
  Value() = default;
  Value(Engine& engine, const std::string& word, const std::string& what) {
    if (word.rfind("v_", 0) == 0) {
      var_ = word.substr(2);
      if (!engine.input->variables().find(var_)) {
        throw InputError("unknown variable '" + var_ + "' for " + what + "; define it before the fix");
      }
    } else {
      value_ = parse_double(word, what);
    }
  }
  bool variable() const { return !var_.empty(); }
  double get(Engine& engine) const {
    return var_.empty() ? value_ : engine.input->variables().compute_equal(var_);
  }

 private:
  double value_ = 0.0;
  std::string var_;
};

class FixGravity : public Fix {
 public:
  FixGravity(Engine& engine, const Args& args) : Fix(engine, args) {
    if (args.size() < 5) throw InputError(std::string("wrong number of arguments; usage: ") + kUsage);
    magnitude_ = Value(engine, args[3], "the gravity magnitude");
    style_ = args[4];
    if (style_ == "vector") {
      require_args(args, 8, 8, kUsage);
      for (int d = 0; d < 3; ++d)
        dir_[d] = Value(engine, args[5 + d], "the gravity direction");
    } else if (style_ == "spherical") {
      require_args(args, 7, 7, kUsage);
      const double phi = parse_double(args[5], "the gravity angle phi") * M_PI / 180.0;
      const double theta = parse_double(args[6], "the gravity angle theta") * M_PI / 180.0;
      set_fixed(Vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)));
    } else if (style_ == "chute") {
      require_args(args, 6, 6, kUsage);
      const double angle = parse_double(args[5], "the chute angle") * M_PI / 180.0;
      set_fixed(Vec3(std::sin(angle), 0.0, -std::cos(angle)));
    } else {
      const std::string hint = did_you_mean(style_, {"vector", "spherical", "chute"});
      throw InputError("unknown fix gravity style '" + style_ + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; usage: " + kUsage);
    }
    if (!variable() && !(direction().norm() > 0.0)) {
      throw InputError("fix " + id + " gravity: the direction vector must not be zero");
    }
    scalar_flag = true;
    size_vector = 3;
  }

  unsigned hooks() const override { return POST_FORCE; }

  void init() override { acc_ = acceleration(); }

  void post_force() override {
    if (variable()) acc_ = acceleration();
    Particles& p = *engine_.particles;
    Vec3* const f = p.f.data();
    const double* const rmass = p.rmass.data();
    const int* const mask = p.mask.data();
    const Vec3 acc = acc_;
    const int bit = groupbit, n = p.nlocal;
    if (group_is_all()) {  // no mask to read
      for (int i = 0; i < n; ++i)
        f[i] += rmass[i] * acc;
      return;
    }
    for (int i = 0; i < n; ++i)
      if (mask[i] & bit) f[i] += rmass[i] * acc;
  }

  /// The acceleration of gravity (x, y, z) [m/s^2] (read by fix buoyancy).
  double compute_vector(int i) override { return i >= 0 && i < 3 ? acceleration()[i] : 0.0; }

  /// Gravitational potential energy of the group (collective).
  double compute_scalar() override {
    const Particles& p = *engine_.particles;
    const Vec3 a = acceleration();
    double local = 0.0;
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & groupbit) local -= p.rmass[i] * a.dot(p.x[i]);
    double all = 0.0;
    MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    return all;
  }

 private:
  void set_fixed(const Vec3& d) {
    fixed_dir_ = d;
    has_fixed_ = true;
  }
  bool variable() const {
    return magnitude_.variable() || dir_[0].variable() || dir_[1].variable() || dir_[2].variable();
  }
  Vec3 direction() const {
    return has_fixed_ ? fixed_dir_ : Vec3(dir_[0].get(engine_), dir_[1].get(engine_), dir_[2].get(engine_));
  }
  Vec3 acceleration() const {
    const Vec3 d = direction();
    const double len = d.norm();
    if (!(len > 0.0)) {
      throw RunError("fix " + id + " gravity: the direction vector given by variables is zero at step " +
                     std::to_string(engine_.update->ntimestep));
    }
    return magnitude_.get(engine_) / len * d;
  }

  std::string style_;
  Value magnitude_;
  Value dir_[3];
  Vec3 fixed_dir_{0, 0, -1};
  bool has_fixed_ = false;
  Vec3 acc_{0, 0, 0};
};

}  // namespace

GRANARY_FIX_STYLE("gravity", FixGravity);

}  // namespace granary
