#include "fix/force_components.h"

#include <mpi.h>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/update.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "particles/particles.h"

namespace granary {

ForceComponents::ForceComponents(Engine& engine, const Args& args, const std::string& style,
                                 const std::string& usage, Options options)
    : engine_(engine), style_(style), options_(options) {
  if (args.size() < 6) throw InputError("fix " + style + " needs three force components; usage: " + usage);
  static const char* names[3] = {"fx", "fy", "fz"};
  for (int d = 0; d < 3; ++d) {
    const std::string& w = args[3 + d];
    if (w == "NULL") {
      if (!options.allow_null)
        throw InputError("fix " + style + ": " + names[d] + " may not be NULL; usage: " + usage);
      kind_[d] = NONE;
    } else if (w.rfind("v_", 0) == 0) {
      var_[d] = w.substr(2);
      if (!engine.input->variables().find(var_[d]))
        throw InputError("fix " + style + ": unknown variable '" + var_[d] + "' for " + names[d] +
                         "; define it before the fix");
      kind_[d] = EQUAL;  // or ATOM: decided in init(), the variable may be redefined
    } else {
      kind_[d] = CONSTANT;
      value_[d] = parse_double(w, std::string("fix ") + style + " " + names[d]);
    }
  }
  for (std::size_t k = 6; k < args.size(); k += 2) {
    const std::string& key = args[k];
    const bool known = key == "region" || (key == "energy" && options.allow_energy);
    if (!known) throw InputError("unknown fix " + style + " keyword '" + key + "'; usage: " + usage);
    if (k + 1 >= args.size())
      throw InputError("fix " + style + " keyword '" + key + "' needs a value; usage: " + usage);
    if (key == "region") {
      region_id_ = args[k + 1];
      engine.domain->region_or_error(region_id_, "fix " + style + " region");
    } else {
      if (args[k + 1].rfind("v_", 0) != 0)
        throw InputError("fix " + style + " energy needs an atom-style variable v_name (got '" + args[k + 1] +
                         "')");
      energy_ = args[k + 1].substr(2);
    }
  }
  if (!energy_.empty() && !any_variable())
    throw InputError("fix " + style +
                     ": the energy keyword is for forces given by variables; with constant forces the "
                     "energy is -x.F and is computed by the fix");
}

bool ForceComponents::any_variable() const {
  for (Kind k : kind_)
    if (k == EQUAL || k == ATOM) return true;
  return false;
}

void ForceComponents::init() {
  Variables& vars = engine_.input->variables();
  for (int d = 0; d < 3; ++d) {
    if (var_[d].empty()) continue;
    if (!vars.find(var_[d]))
      throw InputError("fix " + style_ + ": variable '" + var_[d] + "' does not exist");
    kind_[d] = vars.is_atom(var_[d]) ? ATOM : EQUAL;
    if (kind_[d] == ATOM && !options_.allow_atom)
      throw InputError("fix " + style_ + ": variable '" + var_[d] +
                       "' is atom-style; this fix takes equal-style variables only");
  }
  if (!energy_.empty()) {
    if (!vars.find(energy_))
      throw InputError("fix " + style_ + ": variable '" + energy_ + "' does not exist");
    if (!vars.is_atom(energy_))
      throw InputError("fix " + style_ + ": the energy variable '" + energy_ + "' must be atom-style");
  }
  region_ =
      region_id_.empty() ? nullptr : engine_.domain->region_or_error(region_id_, "fix " + style_ + " region");
}

void ForceComponents::update() {
  Variables& vars = engine_.input->variables();
  for (int d = 0; d < 3; ++d) {
    if (kind_[d] == EQUAL)
      value_[d] = vars.compute_equal(var_[d]);
    else if (kind_[d] == ATOM)
      vars.compute_atom(var_[d], atom_[d]);
  }
  if (!energy_.empty()) vars.compute_atom(energy_, energy_values_);
}

bool ForceComponents::selected(int i, int groupbit) const {
  const Particles& p = *engine_.particles;
  return (p.mask[i] & groupbit) && (!region_ || region_->match(p.x[i]));
}

FixForceComponents::FixForceComponents(Engine& engine, const Args& args, const std::string& usage,
                                       ForceComponents::Options options)
    : Fix(engine, args), comp_(engine, args, args[2], usage, options) {
  size_vector = 3;
}

double FixForceComponents::compute_vector(int i) {
  if (i < 0 || i > 2) return 0.0;
  double all[3];
  MPI_Allreduce(before_, all, 3, MPI_DOUBLE, MPI_SUM, engine_.world);
  return all[i];
}

void FixForceComponents::refuse_clump_sphere(int i) const {
  const Particles& p = *engine_.particles;
  throw RunError("fix " + id + " (" + style + "): particle " + std::to_string(p.id[i]) +
                 " of its group is a sphere of clump " + std::to_string(p.body[i]) + " at step " +
                 std::to_string(engine_.update->ntimestep) + "; fix " + style +
                 " cannot act on clumps. Use a group of free spheres (e.g. group by type), or fix addforce, "
                 "whose force fix multisphere adds to the clump");
}

}  // namespace granary
