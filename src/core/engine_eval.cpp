// Values that expressions, thermo output and styles ask the engine for.
#include <mpi.h>

#include "compute/compute.h"
#include "core/engine.h"

#include "core/atom_properties.h"
#include "core/error.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "core/modify.h"
#include "output/thermo.h"
#include "particles/particles.h"

namespace granary {

double Engine::thermo_keyword(const std::string& name, bool& found) {
  return thermo->keyword_value(name, found);
}

double Engine::compute_value(const std::string& id, int index) {
  Compute* c = modify->compute_or_error(id, "c_" + id);
  const auto step = update->ntimestep;
  if (index == 0) {
    if (!c->scalar_flag) throw InputError("compute " + id + " does not give a global scalar");
    if (c->invoked_scalar != step) {
      c->scalar = c->compute_scalar();
      c->invoked_scalar = step;
    }
    return c->scalar;
  }
  if (c->size_vector == 0) throw InputError("compute " + id + " does not give a global vector");
  if (index < 1 || index > c->size_vector) {
    throw InputError("index " + std::to_string(index) + " of c_" + id + " is out of range 1.." +
                     std::to_string(c->size_vector));
  }
  if (c->invoked_vector != step) {
    c->compute_vector();
    c->invoked_vector = step;
  }
  return c->vector[index - 1];
}

double Engine::fix_value(const std::string& id, int index) {
  Fix* f = modify->fix_or_error(id, "f_" + id);
  if (index == 0) {
    if (!f->scalar_flag) throw InputError("fix " + id + " does not give a global scalar");
    return f->compute_scalar();
  }
  if (index < 1 || index > f->size_vector) {
    throw InputError("index " + std::to_string(index) + " of f_" + id + " is out of range 1.." +
                     std::to_string(f->size_vector));
  }
  return f->compute_vector(index - 1);
}

double Engine::group_function(const std::string& name, const Args& args) {
  auto need = [&](std::size_t n) {
    if (args.size() != n && args.size() != n + 1) {
      throw InputError("group function " + name + "() takes " + std::to_string(n) +
                       " argument(s) plus an optional region");
    }
  };
  auto region_arg = [&](std::size_t n) -> const Region* {
    return args.size() > n ? domain->region_or_error(args[n], name + "()") : nullptr;
  };
  auto dim_of = [&](const std::string& d) {
    if (d == "x") return 0;
    if (d == "y") return 1;
    if (d == "z") return 2;
    throw InputError("group function " + name + "() needs x, y or z, got '" + d + "'");
  };
  if (args.empty()) throw InputError("group function " + name + "() needs a group");
  const int g = groups->find_or_error(args[0], name + "()");
  if (name == "count") {
    need(1);
    return groups->count(g, region_arg(1));
  }
  if (name == "mass") {
    need(1);
    return groups->mass(g, region_arg(1));
  }
  if (name == "xcm" || name == "vcm") {
    need(2);
    const Vec3 v = name == "xcm" ? groups->xcm(g, region_arg(2)) : groups->vcm(g, region_arg(2));
    return v[dim_of(args[1])];
  }
  if (name == "bound") {
    need(2);
    Vec3 lo, hi;
    groups->bounds(g, lo, hi, region_arg(2));
    const std::string& w = args[1];
    if (w.size() == 4 && (w.substr(1) == "min" || w.substr(1) == "max")) {
      const int d = dim_of(w.substr(0, 1));
      return w.substr(1) == "min" ? lo[d] : hi[d];
    }
    throw InputError("bound() needs xmin, xmax, ymin, ymax, zmin or zmax, got '" + w + "'");
  }
  throw InputError("unknown group function '" + name + "'");
}

bool Engine::atom_vector(const std::string& name, std::vector<double>& out) {
  const AtomProperty* prop = find_atom_property(name);
  if (!prop) {
    out.clear();
    return false;
  }
  const int n = particles->nlocal;
  out.resize(n);
  for (int i = 0; i < n; ++i)
    out[i] = prop->value(*this, i);
  return true;
}

void Engine::compute_peratom(const std::string& id, int col, std::vector<double>& out) {
  Compute* c = modify->compute_or_error(id, "c_" + id);
  if (!c->peratom_flag)
    throw InputError("compute " + id + " does not give per-atom values" +
                     (c->local_flag ? std::string(" (it gives local values, one row per contact)") : ""));
  if (c->invoked_peratom != update->ntimestep) {
    c->compute_peratom();
    c->invoked_peratom = update->ntimestep;
  }
  if (col == 0) {
    if (c->peratom_cols != 0)
      throw InputError("c_" + id + " is a per-atom array; give a column c_" + id + "[i]");
    out = c->vector_atom;
  } else {
    if (col < 1 || col > c->peratom_cols) {
      throw InputError("column " + std::to_string(col) + " of c_" + id + " is out of range");
    }
    out = c->array_atom[col - 1];
  }
  out.resize(particles->nlocal);
}

void Engine::fix_peratom(const std::string& id, int col, std::vector<double>& out) {
  Fix* f = modify->fix_or_error(id, "f_" + id);
  if (!f->peratom_flag) throw InputError("fix " + id + " does not give per-atom values");
  if (col > f->peratom_cols)
    throw InputError("column " + std::to_string(col) + " of f_" + id + " is out of range");
  f->peratom(col, out);
  out.resize(particles->nlocal);
}

}  // namespace granary
