#include "fix/fix_wall_gran.h"

#include <cmath>
#include <stdexcept>

#include "contact/contact_kernels.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "particles/particles.h"

namespace granary {

FixWallGran::FixWallGran(Engine& engine, const Args& args) : Fix(engine, args) {
  const std::string usage =
      "fix ID group wall/gran model hertz tangential history [rolling_friction cdt] primitive type T "
      "xplane|yplane|zplane POS | zcylinder RADIUS CX CY";
  std::vector<std::string> words(args.begin() + 3, args.end());
  std::size_t pos = 0;
  try {
    spec_ = contact::parse_model_words(words, pos);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("fix wall/gran: ") + e.what());
  }
  if (pos >= words.size()) throw InputError("fix wall/gran needs a wall; usage: " + usage);
  if (words[pos] == "mesh") {
    throw InputError(
        "fix wall/gran mesh walls need fix mesh/surface, which is not available yet; "
        "use a primitive wall");
  }
  if (words[pos] != "primitive") {
    throw InputError("fix wall/gran: expected 'primitive', got '" + words[pos] + "'; usage: " + usage);
  }
  ++pos;
  if (pos + 1 >= words.size() || words[pos] != "type")
    throw InputError("fix wall/gran primitive needs 'type T'; usage: " + usage);
  wall_type_ = static_cast<int>(parse_int(words[pos + 1], "wall type"));
  if (wall_type_ < 1 || wall_type_ > engine.particles->ntypes) {
    throw InputError("fix wall/gran: wall type " + words[pos + 1] + " is outside 1.." +
                     std::to_string(engine.particles->ntypes));
  }
  pos += 2;
  if (pos >= words.size()) throw InputError("fix wall/gran: missing wall shape; usage: " + usage);
  const std::string& shape = words[pos++];
  auto need = [&](std::size_t n) {
    if (pos + n > words.size())
      throw InputError("fix wall/gran " + shape + " needs " + std::to_string(n) +
                       " value(s); usage: " + usage);
  };
  if (shape == "xplane" || shape == "yplane" || shape == "zplane") {
    need(1);
    shape_ = shape == "xplane" ? Shape::XPlane : shape == "yplane" ? Shape::YPlane : Shape::ZPlane;
    pos_ = parse_double(words[pos++], shape + " position");
  } else if (shape == "zcylinder") {
    need(3);
    shape_ = Shape::ZCylinder;
    cyl_r_ = parse_double(words[pos++], "zcylinder radius");
    cyl_cx_ = parse_double(words[pos++], "zcylinder centre x");
    cyl_cy_ = parse_double(words[pos++], "zcylinder centre y");
    if (cyl_r_ <= 0) throw InputError("fix wall/gran zcylinder radius must be positive");
  } else {
    throw InputError("fix wall/gran: unknown primitive '" + shape +
                     "'; expected xplane, yplane, zplane or zcylinder");
  }
  if (pos != words.size())
    throw InputError("fix wall/gran: unexpected word '" + words[pos] + "'; usage: " + usage);
  nhist_ = contact::history_size(spec_);
  if (nhist_ > 0) {
    field_ =
        engine.particles->add_field("wall_history/" + id + "/" + std::to_string(nhist_), nhist_, false, true);
    engine.particles->extras[field_].history = true;
  }
}

void FixWallGran::init() {
  materials_.build(engine_, spec_, "fix " + id + " wall/gran");
  if (nhist_ > 0) field_ = engine_.particles->find_field("wall_history/" + id + "/" + std::to_string(nhist_));
}

bool FixWallGran::contact(const Vec3& x, double r, double& overlap, Vec3& n) const {
  if (shape_ == Shape::ZCylinder) {
    const double dx = x[0] - cyl_cx_, dy = x[1] - cyl_cy_;
    const double rho = std::sqrt(dx * dx + dy * dy);
    const double gap = std::fabs(rho - cyl_r_);
    if (gap >= r || rho == 0.0) return false;
    overlap = r - gap;
    const double sign = rho < cyl_r_ ? -1.0 : 1.0;  // inside: pushed towards the axis
    n = Vec3(sign * dx / rho, sign * dy / rho, 0.0);
    return true;
  }
  const int d = shape_ == Shape::XPlane ? 0 : shape_ == Shape::YPlane ? 1 : 2;
  const double dist = x[d] - pos_;
  if (std::fabs(dist) >= r) return false;
  overlap = r - std::fabs(dist);
  n.setZero();
  n[d] = dist >= 0 ? 1.0 : -1.0;
  return true;
}

void FixWallGran::post_force() {
  Particles& p = *engine_.particles;
  const double dt = engine_.update->history_dt();
  double* hist_base = nhist_ > 0 ? p.extras[field_].data.data() : nullptr;
  // sub-spheres of clumps use their body's mass (field filled by fix multisphere)
  const int body_mass_field = p.find_field("body_mass");
  const double* body_mass = body_mass_field >= 0 ? p.extras[body_mass_field].data.data() : nullptr;
  // Planes are tested inline (one coordinate per particle); this loop runs for
  // every particle and wall on every step, so no calls or stores unless in contact.
  const bool plane = shape_ != Shape::ZCylinder;
  const int dim = shape_ == Shape::XPlane ? 0 : shape_ == Shape::YPlane ? 1 : 2;
  // local copies: the loop stores forces and history, which would otherwise
  // force the compiler to reload members and vector pointers each iteration
  const Vec3* const x = p.x.data();
  const Vec3* const v = p.v.data();
  const Vec3* const omega = p.omega.data();
  Vec3* const f = p.f.data();
  Vec3* const torque = p.torque.data();
  const double* const radius = p.radius.data();
  const double* const rmass = p.rmass.data();
  const int* const mask = p.mask.data();
  const int* const type = p.type.data();
  const int bit = groupbit;
  const double pos = pos_;
  const int wall_type = wall_type_;
  const contact::ModelSpec spec = spec_;
  const MaterialTable& materials = materials_;
  contact::dispatch_model(spec, [&](auto kernel) {
    using K = decltype(kernel);
    constexpr int nh = K::history_size;
    contact::ContactState c;
    contact::ContactResult res;
    c.dt = dt;
    c.r_j = 0.0;
    c.omega_j.setZero();
    double dummy[6] = {0, 0, 0, 0, 0, 0};
    const int nlocal = p.nlocal;
    for (int i = 0; i < nlocal; ++i) {
      if (!(mask[i] & bit)) continue;
      double* h = nh > 0 ? hist_base + static_cast<std::size_t>(i) * nh : dummy;
      const double r = radius[i];
      double overlap = 0.0;
      Vec3 n;
      bool touching;
      if (plane) {
        const double dist = x[i][dim] - pos;
        touching = dist < r && dist > -r;
        if (touching) {
          overlap = r - std::fabs(dist);
          n.setZero();
          n[dim] = dist >= 0 ? 1.0 : -1.0;
        }
      } else {
        touching = contact(x[i], r, overlap, n);
      }
      if (!touching) {
        if constexpr (nh > 0) {
          bool stale = false;
          for (int q = 0; q < nh; ++q)
            stale |= h[q] != 0.0;
          if (stale)
            for (int q = 0; q < nh; ++q)
              h[q] = 0.0;
        }
        continue;
      }
      c.n = n;
      c.overlap = overlap;
      c.r_i = r;
      c.r_eff = r;
      c.m_eff = body_mass && body_mass[i] > 0.0 ? body_mass[i] : rmass[i];
      c.v_rel = v[i];
      c.omega_i = omega[i];
      K::evaluate(spec, c, materials(type[i], wall_type), h, res);
      f[i] += res.force;
      torque[i] += res.torque_i;
    }
  });
}

GRANARY_FIX_STYLE("wall/gran", FixWallGran);

}  // namespace granary
