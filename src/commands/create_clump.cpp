// The create_clump command: one clump of a particle template at a given
// position, orientation, velocity and spin (integrated by fix multisphere).
#include <Eigen/Geometry>
#include <string>

#include "commands/particle_commands.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "particles/clumps.h"
#include "fix/fix_particle_template.h"
#include "fix/fix_particletemplate_multisphere.h"

namespace granary {

namespace {

using particle_commands::fmt;

// create_clump TEMPLATE-ID x y z [quat w i j k] [vel vx vy vz] [omega wx wy wz] [frame principal|file]
void cmd_create_clump(Engine& e, const Args& a) {
  const std::string usage =
      "create_clump TEMPLATE-ID X Y Z [quat W I J K] [vel VX VY VZ] [omega WX WY WZ] [frame principal|file]";
  e.update->particles_changed();
  if (a.size() < 4) throw InputError("wrong number of arguments; usage: " + usage);
  auto* tmpl = dynamic_cast<FixParticleTemplate*>(e.modify->fix_or_error(a[0], "create_clump"));
  if (!tmpl)
    throw InputError("create_clump: fix " + a[0] + " is not a particle template (particletemplate/...)");
  Clumps* ms = e.clumps;
  if (!ms) throw InputError("create_clump needs fix multisphere to integrate the clump; define it first");
  Vec3 x, v(0, 0, 0), w(0, 0, 0);
  for (int d = 0; d < 3; ++d)
    x[d] = parse_double(a[1 + d], "create_clump position");
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  bool file_frame = false;
  for (std::size_t k = 4; k < a.size();) {
    const std::string& key = a[k];
    if (key == "frame") {
      if (k + 1 >= a.size() || (a[k + 1] != "principal" && a[k + 1] != "file")) {
        throw InputError("create_clump frame takes principal or file; usage: " + usage);
      }
      file_frame = a[k + 1] == "file";
      k += 2;
      continue;
    }
    const std::size_t n = key == "quat" ? 4 : 3;
    if (key != "quat" && key != "vel" && key != "omega") {
      throw InputError("unknown create_clump keyword '" + key + "'; usage: " + usage);
    }
    if (k + n >= a.size())
      throw InputError("create_clump " + key + " needs " + std::to_string(n) + " values");
    double val[4];
    for (std::size_t m = 0; m < n; ++m)
      val[m] = parse_double(a[k + 1 + m], "create_clump " + key);
    if (key == "quat") {
      q = Eigen::Quaterniond(val[0], val[1], val[2], val[3]);
      if (!(q.norm() > 0.0)) throw InputError("create_clump quat must not be zero");
    } else if (key == "vel") {
      v = Vec3(val[0], val[1], val[2]);
    } else {
      w = Vec3(val[0], val[1], val[2]);
    }
    k += n + 1;
  }
  if (file_frame) {
    // quat turns the frame the spheres were given in; the body frame is the principal one
    auto* ms_tmpl = dynamic_cast<FixParticleTemplateMultisphere*>(tmpl);
    if (!ms_tmpl) throw InputError("create_clump frame file needs a particletemplate/multisphere template");
    q = q.normalized() * Eigen::Quaterniond(ms_tmpl->axes());
  }
  const TemplateParticle particle = tmpl->draw();
  const tagint body = ms->create_clump(particle, x, q, v, w);
  e.logger->print("Created clump " + std::to_string(body) + " (" + std::to_string(particle.offsets.size()) +
                  " spheres, mass " + fmt(particle.mass) + " kg)\n");
}

}  // namespace

GRANARY_COMMAND("create_clump", cmd_create_clump);

}  // namespace granary
