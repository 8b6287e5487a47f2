// The set command: per-particle properties of a selection (type, diameter, density, ...).

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/atom_properties.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "domain/region.h"
#include "pair/sph_kernel.h"
#include "particles/particles.h"

#include "commands/particle_commands.h"

namespace granary {

namespace {

using namespace particle_commands;

class Selection {
 public:
  Selection(Engine& e, const std::string& style, const std::string& id, const std::string& cmd) : e_(e) {
    if (style == "atom") {
      style_ = Atom;
      const auto star = id.find('*');
      if (star == std::string::npos) {
        lo_ = hi_ = parse_int(id, cmd + " atom ID");
      } else {
        const std::string a = id.substr(0, star), b = id.substr(star + 1);
        lo_ = a.empty() ? 1 : parse_int(a, cmd + " atom ID range");
        hi_ = b.empty() ? std::numeric_limits<long long>::max() : parse_int(b, cmd + " atom ID range");
      }
    } else if (style == "type") {
      style_ = Type;
      int lo, hi;
      parse_type_range(id, e.particles->ntypes, lo, hi);
      lo_ = lo;
      hi_ = hi;
    } else if (style == "group") {
      style_ = Group;
      bit_ = e.groups->bitmask(e.groups->find_or_error(id, cmd));
    } else if (style == "region") {
      style_ = RegionStyle;
      region_ = e.domain->region_or_error(id, cmd);
    } else {
      const std::string hint = did_you_mean(style, {"atom", "type", "group", "region"});
      throw InputError("unknown " + cmd + " style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; expected atom, type, group or region");
    }
  }

  bool selected(int i) const {
    const Particles& p = *e_.particles;
    switch (style_) {
      case Atom:
        return p.id[i] >= lo_ && p.id[i] <= hi_;
      case Type:
        return p.type[i] >= lo_ && p.type[i] <= hi_;
      case Group:
        return (p.mask[i] & bit_) != 0;
      case RegionStyle:
        return region_->match(p.x[i]);
    }
    return false;
  }

 private:
  enum Style { Atom, Type, Group, RegionStyle };
  Engine& e_;
  Style style_ = Group;
  long long lo_ = 0, hi_ = 0;
  int bit_ = 1;
  const Region* region_ = nullptr;
};

void cmd_set(Engine& e, const Args& a) {
  // the keywords: one per property the table of per-particle properties
  // (core/atom_properties.h) can write, and those with more than one value
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k = settable_atom_property_names();
    for (const char* w :
         {"type/fraction", "omega", "image", "property/atom", "property/peratom", "sphkernel"})
      k.push_back(w);
    return k;
  }();
  static const std::string usage = [] {
    std::string u = "set atom|type|group|region ID keyword value ...  (keywords:";
    for (const std::string& k : keys)
      if (k != "property/peratom") u += " " + k + (k == "property/atom" ? " NAME values" : "");
    return u + ")";
  }();
  begin(e, a, 4, "set", usage.c_str());
  const Selection sel(e, a[0], a[1], "set");
  Particles& p = *e.particles;

  // validate everything first so that a bad keyword changes nothing
  struct Setting {
    std::string key;
    std::vector<double> v;
    std::vector<std::string> var;        // per value: variable name or ""
    std::vector<bool> null;              // image components given as NULL
    int field = -1;                      // property/atom: the per-particle field
    const AtomProperty* prop = nullptr;  // a property of the table with its writer
  };
  std::vector<Setting> settings;
  std::string sph_kernel;  // sphkernel NAME: one kernel for all SPH fixes, not per particle
  for (std::size_t k = 2; k < a.size();) {
    Setting s;
    s.key = a[k];
    if (s.key == "sphkernel") {
      if (!p.sph) throw InputError("set sphkernel needs atom_style sph");
      sph::Kernel kernel;
      if (k + 1 >= a.size() || !sph::kernel_from_name(a[k + 1], kernel))
        throw InputError("set sphkernel needs a kernel name: " + std::string(sph::kernel_names()) +
                         (k + 1 < a.size() ? ", got '" + a[k + 1] + "'" : ""));
      sph_kernel = a[k + 1];
      k += 2;
      continue;
    }
    std::size_t nval = 1;
    if (s.key == "omega" || s.key == "image" || s.key == "type/fraction") nval = 3;
    if (s.key == "property/atom" || s.key == "property/peratom") {
      // a per-particle property of fix property/atom (or of a fix that owns
      // one, e.g. Temp and heatSource of fix heat/gran): its name, then its values
      if (k + 1 >= a.size()) throw InputError("set " + s.key + " needs a property name and its value(s)");
      const std::string& name = a[k + 1];
      s.field = p.find_field(name);
      if (s.field < 0 || !p.extras[s.field].settable) {
        throw InputError("set " + s.key + ": no per-particle property '" + name +
                         "'; define it first with fix property/atom (or the fix that owns it, e.g. fix "
                         "heat/gran for Temp and heatSource)");
      }
      s.key = "property/atom";
      ++k;  // the name; the values follow as for any keyword
      nval = static_cast<std::size_t>(p.extras[s.field].ncomp);
    }
    if (s.key == "meso_rho" && !p.sph) throw InputError("set meso_rho needs atom_style sph");
    s.prop = find_atom_property(s.key);
    if (s.prop && !s.prop->assign) {
      throw InputError("set cannot write '" + s.key +
                       "': it is read-only here (dump custom, compute property/atom and variables read it); "
                       "usage: " +
                       usage);
    }
    if (std::find(keys.begin(), keys.end(), s.key) == keys.end()) {
      const std::string hint = did_you_mean(s.key, keys);
      throw InputError("unknown keyword '" + s.key + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; usage: " + usage);
    }
    if (k + nval >= a.size()) {
      throw InputError("set " + s.key + " needs " + std::to_string(nval) + " value(s)");
    }
    for (std::size_t m = 1; m <= nval; ++m) {
      const std::string& w = a[k + m];
      s.var.push_back(variable_ref(e, w, "set " + s.key));
      s.null.push_back(s.key == "image" && w == "NULL");
      if (!s.var.back().empty()) {
        if (s.key == "type/fraction" || s.key == "image") {
          throw InputError("set " + s.key + " does not take variables; give numbers");
        }
        s.v.push_back(0.0);
      } else if (s.null.back()) {
        s.v.push_back(0.0);
      } else if ((s.prop && s.prop->check == SetCheck::Type) || (s.key == "type/fraction" && m == 1)) {
        s.v.push_back(parse_type(e, w, "set type"));
      } else if (s.key == "image" || (s.key == "type/fraction" && m == 3)) {
        s.v.push_back(static_cast<double>(parse_int(w, "set " + s.key)));
      } else {
        s.v.push_back(parse_double(w, "set " + s.key));
      }
    }
    if (s.prop && s.prop->check == SetCheck::Positive && s.var[0].empty() && !(s.v[0] > 0.0)) {
      throw InputError("set " + s.key + " must be positive, got '" + a[k + 1] + "'");
    }
    if (s.key == "type/fraction") {
      if (s.v[1] < 0.0 || s.v[1] > 1.0) throw InputError("set type/fraction needs a fraction in [0, 1]");
      if (s.v[2] <= 0.0) throw InputError("set type/fraction needs a positive seed");
    }
    settings.push_back(std::move(s));
    k += nval + 1;
  }

  e.logger->print("Setting atom values ...\n");
  if (!sph_kernel.empty()) p.sph_kernel = sph_kernel;
  for (const Setting& s : settings) {
    // per-atom values of variables, evaluated before this keyword changes anything
    std::vector<std::vector<double>> varvals(s.var.size());
    for (std::size_t c = 0; c < s.var.size(); ++c) {
      if (s.var[c].empty()) continue;
      e.input->variables().compute_atom(s.var[c], varvals[c]);
      varvals[c].resize(p.nlocal, 0.0);
    }
    auto value = [&](std::size_t c, int i) { return s.var[c].empty() ? s.v[c] : varvals[c][i]; };
    const std::string& key = s.key;
    bool any_var = false;
    for (const auto& v : s.var)
      any_var |= !v.empty();
    if (any_var) {
      // variable values are checked on every rank before anything is set
      long long bad = 0;
      for (int i = 0; i < p.nlocal; ++i) {
        if (!sel.selected(i)) continue;
        const double v = value(0, i);
        const SetCheck check = s.prop ? s.prop->check : SetCheck::Any;
        if (check == SetCheck::Type && (static_cast<int>(v) < 1 || static_cast<int>(v) > p.ntypes)) ++bad;
        if (check == SetCheck::Positive && !(v > 0.0)) ++bad;
        for (std::size_t c = 0; c < s.var.size(); ++c)
          if (!std::isfinite(value(c, i))) ++bad;
      }
      bad = sum_all(e, bad);
      if (bad > 0) {
        throw InputError("set " + key + ": the variable gives " + std::to_string(bad) +
                         " invalid value(s) (types must be in 1.." + std::to_string(p.ntypes) +
                         ", sizes and masses positive)");
      }
    }
    long long count = 0;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!sel.selected(i)) continue;
      if (s.prop) {
        s.prop->assign(e, i, value(0, i));
      } else if (key == "type/fraction") {
        if (hash01(static_cast<long long>(s.v[2]), p.id[i]) >= s.v[1]) continue;
        p.type[i] = static_cast<int>(s.v[0]);
      } else if (key == "omega") {
        p.omega[i] = Vec3(value(0, i), value(1, i), value(2, i));
      } else if (key == "property/atom") {
        double* dst = &p.extras[s.field].data[static_cast<std::size_t>(i) * s.v.size()];
        for (std::size_t c = 0; c < s.v.size(); ++c)
          dst[c] = value(c, i);
      } else if (key == "image") {
        int img[3];
        Particles::image_unpack(p.image[i], img[0], img[1], img[2]);
        for (int d = 0; d < 3; ++d)
          if (!s.null[d]) img[d] = static_cast<int>(s.v[d]);
        p.image[i] = Particles::image_pack(img[0], img[1], img[2]);
      }
      ++count;
    }
    count = sum_all(e, count);
    e.logger->print("  " + std::to_string(count) + " settings made for " + s.key + "\n");
  }
}

// --------------------------------------------------------------- velocity

}  // namespace

GRANARY_COMMAND("set", cmd_set);

}  // namespace granary
