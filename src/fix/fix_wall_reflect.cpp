// fix ID group wall/reflect FACE ARG ... [units lattice|box]
//
// FACE = xlo xhi ylo yhi zlo zhi; ARG = EDGE (the box face), a coordinate, or
// an equal-style variable v_name evaluated every step. After the drift of each
// step, a particle of the group whose centre has passed a lo (hi) wall by a
// distance d is put back inside by d and the sign of its velocity component
// normal to the wall is flipped. Coordinates and variables are in lattice
// spacings with units lattice (the default, as in LIGGGHTS; spacing 1 without
// a lattice command) or in m with units box. Clumps are refused.
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group wall/reflect xlo|xhi|ylo|yhi|zlo|zhi EDGE|COORD|v_name ... [units lattice|box]";

class FixWallReflect : public Fix {
 public:
  FixWallReflect(Engine& engine, const Args& args) : Fix(engine, args) {
    static const char* faces[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
    bool lattice = true, units_given = false;
    for (std::size_t k = 3; k < args.size(); k += 2) {
      const std::string& key = args[k];
      if (k + 1 >= args.size())
        throw InputError("fix wall/reflect: '" + key + "' needs a value; usage: " + kUsage);
      const std::string& val = args[k + 1];
      if (key == "units") {
        if (val != "box" && val != "lattice")
          throw InputError("fix wall/reflect units must be box or lattice (got '" + val + "')");
        lattice = val == "lattice";
        units_given = true;
        continue;
      }
      int face = -1;
      for (int f = 0; f < 6; ++f)
        if (key == faces[f]) face = f;
      if (face < 0) {
        const std::string hint = did_you_mean(key, {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi", "units"});
        throw InputError("unknown fix wall/reflect face or keyword '" + key + "'" +
                         (hint.empty() ? "" : "; " + hint) + "; usage: " + kUsage);
      }
      for (const Wall& w : walls_)
        if (w.face == face)
          throw InputError(std::string("fix wall/reflect: wall ") + faces[face] + " given twice");
      const int dim = face / 2;
      if (engine.domain->periodic[dim])
        throw InputError(std::string("fix wall/reflect: wall ") + faces[face] +
                         " in a periodic dimension; make the boundary fixed (f) or shrink-wrapped (s, m)");
      Wall w;
      w.face = face;
      if (val == "EDGE") {
        w.edge = true;
      } else if (val.rfind("v_", 0) == 0) {
        w.var = val.substr(2);
        if (!engine.input->variables().find(w.var))
          throw InputError("fix wall/reflect: unknown variable '" + w.var + "' for wall " + faces[face] +
                           "; define it before the fix");
      } else {
        w.coord = parse_double(val, std::string("the position of wall ") + faces[face]);
      }
      walls_.push_back(w);
    }
    if (walls_.empty())
      throw InputError(std::string("fix wall/reflect needs at least one wall; usage: ") + kUsage);
    const Domain& dom = *engine.domain;
    if (lattice && units_given && dom.lattice_style == "none")
      throw InputError(
          "fix wall/reflect uses units lattice but no lattice is defined; add a lattice command "
          "before it or use units box");
    for (int d = 0; d < 3; ++d)
      scale_[d] = lattice ? dom.lattice_spacing[d] : 1.0;
  }

  unsigned hooks() const override { return POST_INTEGRATE; }

  void init() override {
    for (const Wall& w : walls_) {
      if (w.var.empty()) continue;
      if (!engine_.input->variables().find(w.var))
        throw InputError("fix wall/reflect: variable '" + w.var + "' does not exist");
      if (engine_.input->variables().is_atom(w.var))
        throw InputError("fix wall/reflect: variable '" + w.var +
                         "' is atom-style; it needs an equal-style one");
    }
  }

  void post_integrate() override {
    Particles& p = *engine_.particles;
    const Domain& dom = *engine_.domain;
    for (const Wall& w : walls_) {
      const int dim = w.face / 2;
      const bool lo = w.face % 2 == 0;
      double c;
      if (w.edge)
        c = lo ? dom.boxlo[dim] : dom.boxhi[dim];
      else if (!w.var.empty())
        c = engine_.input->variables().compute_equal(w.var) * scale_[dim];
      else
        c = w.coord * scale_[dim];
      for (int i = 0; i < p.nlocal; ++i) {
        if (!(p.mask[i] & groupbit)) continue;
        const double x = p.x[i][dim];
        if (lo ? x >= c : x <= c) continue;
        if (p.body[i] >= 0)
          throw RunError("fix " + id + " (wall/reflect): particle " + std::to_string(p.id[i]) +
                         " is a sphere of clump " + std::to_string(p.body[i]) + " at step " +
                         std::to_string(engine_.update->ntimestep) +
                         "; wall/reflect cannot reflect clumps. Use fix wall/gran for clumps");
        p.x[i][dim] = 2.0 * c - x;
        p.v[i][dim] = -p.v[i][dim];
      }
    }
  }

 private:
  struct Wall {
    int face = 0;
    bool edge = false;
    double coord = 0.0;
    std::string var;
  };
  std::vector<Wall> walls_;
  double scale_[3] = {1, 1, 1};
};

}  // namespace

GRANARY_FIX_STYLE("wall/reflect", FixWallReflect);

}  // namespace granary
