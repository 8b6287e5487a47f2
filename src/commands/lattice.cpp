// The lattice command (lattice sc|bcc|fcc|sq|sq2|none ...): the lattice create_atoms fills.

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "domain/domain.h"

#include "commands/particle_commands.h"

namespace granary {

namespace {

using namespace particle_commands;

void cmd_lattice(Engine& e, const Args& a) {
  const char* usage = "lattice none [SCALE] | lattice sc|bcc|fcc|sq|sq2 SCALE [origin X Y Z]";
  if (a.empty()) throw InputError("lattice needs a style; usage: " + std::string(usage));
  Domain& dom = *e.domain;
  const std::string& style = a[0];
  std::vector<Vec3> basis;
  if (style == "sc") {
    basis = {Vec3(0, 0, 0)};
  } else if (style == "bcc") {
    basis = {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0.5)};
  } else if (style == "fcc") {
    basis = {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0), Vec3(0.5, 0, 0.5), Vec3(0, 0.5, 0.5)};
  } else if (style == "sq") {
    basis = {Vec3(0, 0, 0)};
  } else if (style == "sq2") {
    basis = {Vec3(0, 0, 0), Vec3(0.5, 0.5, 0)};
  } else if (style != "none") {
    const std::vector<std::string> known = {"none", "sc", "bcc", "fcc", "sq", "sq2"};
    const std::string hint = did_you_mean(style, known);
    throw InputError("unknown lattice style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                     "; usage: " + usage);
  }
  const bool planar = style == "sq" || style == "sq2";
  if (style != "none" && planar != (dom.dimension == 2))
    throw InputError("lattice " + style + " is a " + (planar ? "2d" : "3d") +
                     " lattice but the simulation is " + std::to_string(dom.dimension) + "d; use " +
                     (planar ? "sc, bcc or fcc" : "sq or sq2") + " (or dimension " + (planar ? "2" : "3") +
                     " before the box)");
  if (style == "none") {
    require_args(a, 1, 2, usage);
  } else if (a.size() < 2) {
    throw InputError("lattice " + style + " needs the lattice constant; usage: " + usage);
  }
  // origin X Y Z: the lattice shifted by these fractions of a cell (each in [0, 1))
  Vec3 origin = Vec3::Zero();
  for (std::size_t k = 2; k < a.size();) {
    if (a[k] != "origin") {
      throw InputError("unknown lattice keyword '" + a[k] + "'; usage: " + usage);
    }
    if (k + 3 >= a.size())
      throw InputError("lattice origin needs three values; usage: " + std::string(usage));
    for (int d = 0; d < 3; ++d) {
      origin[d] = parse_double(a[k + 1 + d], "lattice origin");
      if (!(origin[d] >= 0.0 && origin[d] < 1.0)) {
        throw InputError("lattice origin values are fractions of a cell in [0, 1), got '" + a[k + 1 + d] +
                         "'");
      }
    }
    k += 4;
  }
  if (planar && origin[2] != 0.0)
    throw InputError("lattice " + style + ": the z origin of a 2d lattice must be 0");
  for (Vec3& b : basis)
    b += origin;
  const double scale = a.size() >= 2 ? parse_double(a[1], "the lattice constant") : 1.0;
  if (!(scale > 0.0)) throw InputError("the lattice constant must be positive, got '" + a[1] + "'");
  dom.lattice_style = style;
  dom.lattice_basis = basis;
  for (double& s : dom.lattice_spacing)
    s = scale;
  if (style != "none") {
    e.logger->print("Lattice spacing in x,y,z = " + fmt(scale) + " " + fmt(scale) + " " + fmt(scale) + "\n");
  }
}

}  // namespace

GRANARY_COMMAND("lattice", cmd_lattice);

}  // namespace granary
