// fix ID group move linear|wiggle|rotate ... [units box|lattice] (LAMMPS,
// LIGGGHTS): the particles of the group follow a prescribed motion from
// their positions when the fix was defined (unwrapped with the image flags),
// whatever the forces:
//   linear Vx Vy Vz:            x = x0 + V t,                v = V
//   wiggle Ax Ay Az period:     x = x0 + A sin(w t),         v = A w cos(w t),  w = 2 pi / period
//   rotate Px Py Pz Rx Ry Rz period: x = P + rotation by w t about the axis R through P of (x0 - P),
//                               v = w x (x - P), omega = w (the spin is set too)
// with t the time since the fix was defined. A NULL component of linear or
// wiggle is integrated as fix nve/sphere would (velocity-Verlet with its
// force). The spins of linear and wiggle particles are left as they are
// (torques do not turn them; LIGGGHTS 3.8, measured). The original
// positions and the start time are kept in restart files: defined again
// with the same ID after read_restart, the fix continues the motion. See
// doc/fixes/move.md.
#include <cmath>
#include <memory>
#include <sstream>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "domain/origin_field.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixMove : public Fix {
 public:
  FixMove(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group move linear VX VY VZ | wiggle AX AY AZ PERIOD | rotate PX PY PZ RX RY RZ PERIOD "
        "[units box|lattice]";
    if (args.size() < 4)
      throw InputError("wrong number of arguments for fix " + id + " move; usage: " + usage);
    const std::string& style = args[3];
    std::size_t nargs = 0;
    if (style == "linear") {
      style_ = kLinear, nargs = 3;
    } else if (style == "wiggle") {
      style_ = kWiggle, nargs = 4;
    } else if (style == "rotate") {
      style_ = kRotate, nargs = 7;
    } else if (style == "variable") {
      throw InputError("fix " + id +
                       " move: the variable style is not supported; use linear, wiggle or rotate");
    } else {
      const std::string hint = did_you_mean(style, {"linear", "wiggle", "rotate"});
      throw InputError("unknown fix move style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; usage: " + usage);
    }
    if (args.size() < 4 + nargs)
      throw InputError("fix " + id + " move " + style + " needs " + std::to_string(nargs) +
                       " values; usage: " + usage);
    bool lattice = false;
    for (std::size_t k = 4 + nargs; k < args.size(); k += 2) {
      if (args[k] != "units" || k + 1 >= args.size())
        throw InputError("unknown fix move keyword '" + args[k] + "'; usage: " + usage);
      if (args[k + 1] == "lattice")
        lattice = true;
      else if (args[k + 1] != "box")
        throw InputError("fix " + id + " move: units must be box or lattice, got '" + args[k + 1] + "'");
    }
    const Domain& dom = *engine.domain;
    if (lattice && dom.lattice_style == "none")
      throw InputError("fix " + id + " move: units lattice needs a lattice; add one or use units box");
    auto scale = [&](int d) { return lattice ? dom.lattice_spacing[d] : 1.0; };
    auto value = [&](std::size_t k, const std::string& what) {
      return parse_double(args[k], "the " + what + " of fix " + id + " move");
    };
    if (style_ == kLinear || style_ == kWiggle) {
      for (int d = 0; d < 3; ++d) {
        if (args[4 + d] == "NULL") {
          prescribed_[d] = false;
          continue;
        }
        vec_[d] = value(4 + d, style_ == kLinear ? "velocity" : "amplitude") * scale(d);
      }
      if (style_ == kWiggle) period_ = value(7, "period");
    } else {
      for (int d = 0; d < 3; ++d) {
        point_[d] = value(4 + d, "axis point") * scale(d);
        axis_[d] = value(7 + d, "axis");
      }
      if (!(axis_.norm() > 0.0)) throw InputError("fix " + id + " move rotate: the axis must not be zero");
      axis_.normalize();
      period_ = value(10, "period");
    }
    if (style_ != kLinear && !(period_ > 0.0))
      throw InputError("fix " + id + " move " + style + ": the period must be positive");
    time_integrate = true;
    restart_global = true;
    t0_ = engine.update->time();
    origin_ = std::make_unique<OriginField>(engine, "move/" + id);
  }

  unsigned hooks() const override { return INITIAL_INTEGRATE | FINAL_INTEGRATE; }
  void unfixed() override { origin_->release(); }

  void setup() override { require_free_spheres(); }

  void initial_integrate() override {
    Particles& p = *engine_.particles;
    const Domain& dom = *engine_.domain;
    const double dt = engine_.update->dt, dtf = 0.5 * dt;
    const double t = engine_.update->time() - t0_;  // at the end of this step
    const double w = style_ == kLinear ? 0.0 : 2.0 * M_PI / period_;
    const double c = std::cos(w * t), s = std::sin(w * t);
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      int im[3];
      Particles::image_unpack(p.image[i], im[0], im[1], im[2]);
      const Vec3 shift(im[0] * dom.prd[0], im[1] * dom.prd[1], im[2] * dom.prd[2]);
      const Vec3 x0 = origin_->at(i);
      if (style_ == kRotate) {
        const Vec3 r = x0 - point_;
        const Vec3 xu = point_ + r * c + axis_.cross(r) * s + axis_ * (axis_.dot(r) * (1.0 - c));
        p.x[i] = xu - shift;
        p.v[i] = (w * axis_).cross(xu - point_);
        p.omega[i] = w * axis_;
        continue;
      }
      const double dtfm = dtf / p.rmass[i];
      for (int d = 0; d < 3; ++d) {
        if (!prescribed_[d]) {
          p.v[i][d] += dtfm * p.f[i][d];
          p.x[i][d] += dt * p.v[i][d];
        } else if (style_ == kLinear) {
          p.x[i][d] = x0[d] + vec_[d] * t - shift[d];
          p.v[i][d] = vec_[d];
        } else {
          p.x[i][d] = x0[d] + vec_[d] * s - shift[d];
          p.v[i][d] = vec_[d] * w * c;
        }
      }
    }
  }

  void final_integrate() override {
    if (style_ == kRotate) return;
    Particles& p = *engine_.particles;
    const double dtf = 0.5 * engine_.update->dt;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const double dtfm = dtf / p.rmass[i];
      for (int d = 0; d < 3; ++d)
        if (!prescribed_[d]) p.v[i][d] += dtfm * p.f[i][d];
    }
  }

  void pack_restart(std::string& out) const override {
    std::ostringstream os;
    os.precision(17);
    os << t0_;
    out = os.str();
  }
  void unpack_restart(const std::string& in) override {
    std::istringstream is(in);
    double t0;
    if (is >> t0) t0_ = t0;
  }

 private:
  enum Style { kLinear, kWiggle, kRotate };
  Style style_ = kLinear;
  Vec3 vec_{0, 0, 0};  // velocity (linear) or amplitude (wiggle)
  bool prescribed_[3] = {true, true, true};
  Vec3 point_{0, 0, 0}, axis_{0, 0, 1};
  double period_ = 0.0;
  double t0_ = 0.0;  // simulated time when the fix was defined
  std::unique_ptr<OriginField> origin_;
};

}  // namespace

GRANARY_FIX_STYLE("move", FixMove);

}  // namespace granary
