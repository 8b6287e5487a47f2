// fix ID group wall/region region-ID style epsilon sigma cutoff (LIGGGHTS 3.8
// and LAMMPS syntax): the surface of a region as a wall pushing the group's
// particles with a potential of their distance r to it (lj93, lj126, colloid,
// harmonic; shifted to 0 at r = cutoff). The distance and the direction are
// those of the nearest point of each face of the region within the cutoff
// (Region::surface). Global scalar: the wall energy; global vector (3): the
// force of the particles on the wall. See doc/fixes/wall_region.md.
#include <mpi.h>

#include <cmath>
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

const char* const kUsage =
    "fix ID group-ID wall/region region-ID lj93|lj126|colloid|harmonic epsilon sigma cutoff";

enum class Style { Lj93, Lj126, Colloid, Harmonic };

class FixWallRegion : public Fix {
 public:
  FixWallRegion(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string what = where();
    if (args.size() != 8)
      throw InputError(what + ": expected " + std::to_string(5) + " arguments after the style, got " +
                       std::to_string(args.size() - 3) + "; usage: " + kUsage);
    region_id_ = args[3];
    engine.domain->region_or_error(region_id_, what);
    const std::string& s = args[4];
    if (s == "lj93")
      style_ = Style::Lj93;
    else if (s == "lj126")
      style_ = Style::Lj126;
    else if (s == "colloid")
      style_ = Style::Colloid;
    else if (s == "harmonic")
      style_ = Style::Harmonic;
    else
      throw InputError(what + ": unknown wall style '" + s + "'; expected lj93, lj126, colloid or harmonic");
    epsilon_ = parse_double(args[5], what + " epsilon");
    sigma_ = parse_double(args[6], what + " sigma");
    cutoff_ = parse_double(args[7], what + " cutoff");
    if (!(cutoff_ > 0.0)) throw InputError(what + ": the cutoff must be positive, got '" + args[7] + "'");
    if (style_ != Style::Harmonic && !(sigma_ > 0.0))
      throw InputError(what + ": sigma must be positive for style " + s + ", got '" + args[6] + "'");
    scalar_flag = true;
    size_vector = 3;
  }

  unsigned hooks() const override { return POST_FORCE; }

  void init() override { region_ = engine_.domain->region_or_error(region_id_, where()); }

  void post_force() override {
    Particles& p = *engine_.particles;
    energy_ = 0.0;
    wall_force_ = Vec3::Zero();
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const Vec3& x = p.x[i];
      if (!region_->match(x))
        fail(i, "is not in region " + region_id_ + (region_->interior ? "" : " (side out)"));
      region_->surface(x, cutoff_, points_);
      for (const Region::SurfacePoint& s : points_) {
        double f = 0.0, e = 0.0;
        if (!wall(s.r, p.radius[i], f, e)) {
          fail(i, style_ == Style::Colloid
                      ? "touches the surface of region " + region_id_ + " (its distance " +
                            format_number(s.r) + " m is not more than its radius)"
                      : "is on the surface of region " + region_id_);
        }
        // f > 0 pushes the particle away from the surface
        const Vec3 force = (f / s.r) * s.del;
        p.f[i] += force;
        wall_force_ -= force;
        energy_ += e;
      }
    }
  }

  double compute_scalar() override {
    double all = 0.0;
    MPI_Allreduce(&energy_, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    return all;
  }

  double compute_vector(int k) override {
    if (k < 0 || k > 2) return 0.0;
    const std::int64_t step = engine_.update->ntimestep;
    if (step != summed_step_) {
      MPI_Allreduce(wall_force_.data(), summed_.data(), 3, MPI_DOUBLE, MPI_SUM, engine_.world);
      summed_step_ = step;
    }
    return summed_[k];
  }

 private:
  std::string where() const { return "fix " + id + " wall/region"; }
  [[noreturn]] void fail(int i, const std::string& what) const {
    const Particles& p = *engine_.particles;
    throw RunError(where() + ": particle " + std::to_string(p.id[i]) + " at (" + format_number(p.x[i][0]) +
                   ", " + format_number(p.x[i][1]) + ", " + format_number(p.x[i][2]) + ") " + what +
                   " at step " + std::to_string(engine_.update->ntimestep) +
                   "; the wall acts on particles on its region's side of the surface only: start them "
                   "farther inside, or stiffen the wall (epsilon) so that they stay there");
  }

  /// Energy of a particle of radius `rad` at distance r from the surface,
  /// unshifted; false where it is not defined (r <= 0, colloid: r <= rad).
  bool energy(double r, double rad, double& e) const {
    switch (style_) {
      case Style::Lj93: {
        if (!(r > 0.0)) return false;
        const double s3 = std::pow(sigma_ / r, 3);
        e = epsilon_ * (2.0 / 15.0 * s3 * s3 * s3 - s3);
        return true;
      }
      case Style::Lj126: {
        if (!(r > 0.0)) return false;
        const double s6 = std::pow(sigma_ / r, 6);
        e = 4.0 * epsilon_ * (s6 * s6 - s6);
        return true;
      }
      case Style::Colloid: {
        const double d = r - rad, R = rad;
        if (!(d > 0.0)) return false;
        const double d2r = d + 2.0 * R;
        const double s6 = std::pow(sigma_, 6);
        e = epsilon_ * (s6 / 7560.0 * ((6.0 * R - d) / std::pow(d, 7) + (d + 8.0 * R) / std::pow(d2r, 7)) -
                        (2.0 * R * (d + R) + d * d2r * (std::log(d) - std::log(d2r))) / (6.0 * d * d2r));
        return true;
      }
      case Style::Harmonic:
        if (!(r > 0.0)) return false;
        e = epsilon_ * (r - cutoff_) * (r - cutoff_);
        return true;
    }
    return false;
  }

  /// Force -dE/dr (positive: away from the surface) and shifted energy
  /// E(r) - E(cutoff) at distance r; false where the potential is not defined.
  bool wall(double r, double rad, double& f, double& e) const {
    double ecut = 0.0;
    if (!energy(r, rad, e)) return false;
    if (!energy(cutoff_, rad, ecut)) ecut = 0.0;
    e -= ecut;
    switch (style_) {
      case Style::Lj93: {
        const double s3 = std::pow(sigma_ / r, 3);
        f = epsilon_ * (6.0 / 5.0 * s3 * s3 * s3 - 3.0 * s3) / r;
        break;
      }
      case Style::Lj126: {
        const double s6 = std::pow(sigma_ / r, 6);
        f = 24.0 * epsilon_ * (2.0 * s6 * s6 - s6) / r;
        break;
      }
      case Style::Colloid: {
        // -dE/dD with D = r - R: the derivative of the documented energy
        const double d = r - rad, R = rad;
        const double d2r = d + 2.0 * R;
        const double s6 = std::pow(sigma_, 6);
        const double de =
            s6 / 7560.0 * ((6.0 * d - 42.0 * R) / std::pow(d, 8) - (6.0 * d + 54.0 * R) / std::pow(d2r, 8)) +
            2.0 * R * R * R / (3.0 * d * d * d2r * d2r);
        f = -epsilon_ * de;
        break;
      }
      case Style::Harmonic:
        f = 2.0 * epsilon_ * (cutoff_ - r);
        break;
    }
    return true;
  }

  std::string region_id_;
  const Region* region_ = nullptr;
  Style style_ = Style::Lj93;
  double epsilon_ = 0.0, sigma_ = 0.0, cutoff_ = 0.0;
  std::vector<Region::SurfacePoint> points_;
  double energy_ = 0.0;
  Vec3 wall_force_ = Vec3::Zero();
  Vec3 summed_ = Vec3::Zero();
  std::int64_t summed_step_ = -1;
};

}  // namespace

GRANARY_FIX_STYLE("wall/region", FixWallRegion);

}  // namespace granary
