// Original positions kept per particle (compute displace/atom, compute msd,
// fix spring/self): a per-particle field of 3 values (unwrapped across
// periodic boundaries with the image flags) that migrates with its particle
// and is written to restart files under its name, so that the style defined
// again with the same ID after read_restart goes on from the same origins.
// Every particle present when the style is defined gets its current
// position; a particle created later (insertion, create_atoms) gets its
// position when the style first asks for its origin.
#pragma once

#include <cmath>
#include <limits>
#include <string>

#include "core/engine.h"
#include "domain/groups.h"
#include "particles/particles.h"

namespace granary {

class OriginField {
 public:
  /// `name`: the field's name, unique to its style and ID (e.g. "origin/ID").
  OriginField(Engine& engine, const std::string& name) : engine_(engine), name_(name) {
    Particles& p = *engine.particles;
    const bool restored = p.find_field(name_) >= 0;  // read from a restart file
    field_ = p.add_field(name_, 3, false, true);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    p.extras[field_].init = {nan, nan, nan};
    if (!restored) {
      for (int i = 0; i < p.nlocal; ++i)
        set(i, engine.groups->unwrapped(i));
    }
  }

  /// The original position of owned particle i; a particle that has none yet
  /// (created after the style) gets its current position now.
  Vec3 at(int i) {
    double* d = data() + 3 * static_cast<std::size_t>(i);
    if (std::isnan(d[0])) set(i, engine_.groups->unwrapped(i));
    return Vec3(d[0], d[1], d[2]);
  }

  void release() { engine_.particles->release_field(name_); }

 private:
  double* data() const { return engine_.particles->extras[field_].data.data(); }
  void set(int i, const Vec3& x) {
    double* d = data() + 3 * static_cast<std::size_t>(i);
    d[0] = x[0];
    d[1] = x[1];
    d[2] = x[2];
  }

  Engine& engine_;
  std::string name_;
  int field_ = -1;
};

}  // namespace granary
