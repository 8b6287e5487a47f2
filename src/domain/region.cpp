// Region base class: the keywords shared by every region style, coordinate
// parsing with INF/EDGE and lattice scaling. The `region` command itself
// (Domain::add_region) looks the style up in the region registry.
#include "domain/region.h"

#include <cctype>

#include "core/engine.h"
#include "core/error.h"
#include "domain/domain.h"
#include "domain/region_util.h"

namespace granary {

Region::Region(Engine& engine, const Args& args, std::size_t nshape) : engine_(engine) {
  if (args.size() < 2) {
    throw InputError("usage: region ID style args... [side in|out] [units box|lattice]");
  }
  id = args[0];
  style = args[1];
  for (char c : id) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) {
      throw InputError("region ID '" + id + "' may use only letters, digits and underscores");
    }
  }
  if (args.size() < 2 + nshape) {
    throw InputError("region " + style + " needs " + std::to_string(nshape) +
                     " arguments after the style name, got " + std::to_string(args.size() - 2) +
                     "; see doc/commands/region.md");
  }
  // a keyword among the shape's numbers: the shape is short of numbers (the
  // keyword's value would otherwise be reported as an unknown keyword)
  for (std::size_t k = 2; k < 2 + nshape; ++k) {
    if (args[k] == "side" || args[k] == "units") {
      throw InputError("region " + id + " (" + style + ") needs " + std::to_string(nshape) +
                       " numbers after the style name but has " + std::to_string(k - 2) + " before '" +
                       args[k] + "'; see doc/commands/region.md");
    }
  }
  bool lattice = false;
  for (std::size_t k = 2 + nshape; k < args.size(); k += 2) {
    const std::string& key = args[k];
    if (key != "side" && key != "units") {
      std::string msg = "unknown keyword '" + key + "' in region " + id + " (" + style +
                        "); expected side in|out or units box|lattice";
      if (key == "move" || key == "rotate" || key == "open") {
        msg = "region keyword '" + key + "' is not supported; regions are static";
      }
      throw InputError(msg);
    }
    if (k + 1 >= args.size()) {
      throw InputError("region keyword '" + key + "' needs a value");
    }
    const std::string& value = args[k + 1];
    if (key == "side") {
      if (value == "in") {
        interior = true;
      } else if (value == "out") {
        interior = false;
      } else {
        throw InputError("region side must be in or out, got '" + value + "'");
      }
    } else {
      if (value == "box") {
        lattice = false;
      } else if (value == "lattice") {
        lattice = true;
      } else {
        throw InputError("region units must be box or lattice, got '" + value + "'");
      }
    }
  }
  if (lattice) {
    const Domain& dom = *engine.domain;
    if (dom.lattice_style == "none") {
      throw InputError("region " + id +
                       " uses units lattice but no lattice is defined; add a lattice command "
                       "before it or use units box");
    }
    for (int d = 0; d < 3; ++d)
      scale[d] = dom.lattice_spacing[d];
  }
}

double Region::coord(const std::string& word, int dim, bool lower) const {
  if (word == "INF" || (lower && word == "-INF") || (!lower && word == "+INF")) {
    return lower ? -region_util::kBig : region_util::kBig;
  }
  if (word == "EDGE") {
    const Domain& dom = *engine_.domain;
    if (!dom.box_exist) {
      throw InputError("region " + id +
                       ": EDGE refers to the simulation box, which does not exist yet; create "
                       "the box first or give a number");
    }
    return lower ? dom.boxlo[dim] : dom.boxhi[dim];
  }
  const std::string what = std::string("the ") + (lower ? "lower " : "upper ") + "xyz"[dim] +
                           " bound of region " + id + " (a number, INF or EDGE)";
  return parse_double(word, what) * scale[dim];
}

double Region::length(const std::string& word, int dim) const {
  return parse_double(word, "a length of region " + id) * scale[dim];
}

void Region::surface_interior(const Vec3&, double, std::vector<SurfacePoint>&) const {
  throw InputError("region " + id + " (" + style +
                   ") has no surface for walls; use a block, cylinder, cone, sphere or plane");
}

void Region::surface_exterior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const {
  surface_interior(x, cutoff, out);
}

}  // namespace granary
