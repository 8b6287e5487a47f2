// fix ID group multicontact/halfspace [geometric_prefactor GAMMA]
// (see fix_multicontact_halfspace.h and doc/fixes/multicontact_halfspace.md)
#include "fix/fix_multicontact_halfspace.h"

#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/global_property.h"
#include "core/modify.h"
#include "core/registry.h"
#include "particles/particles.h"

namespace granary {

namespace {
const char* kUsage = "fix ID group multicontact/halfspace [geometric_prefactor GAMMA]";
}  // namespace

FixMulticontactHalfspace::FixMulticontactHalfspace(Engine& engine, const Args& args) : Fix(engine, args) {
  double gamma = 1.125;  // LIGGGHTS 3.8's default (measured)
  for (std::size_t k = 3; k < args.size(); k += 2) {
    if (args[k] != "geometric_prefactor")
      throw InputError("fix multicontact/halfspace: unknown keyword '" + args[k] + "'; usage: " + kUsage);
    if (k + 1 >= args.size())
      throw InputError("fix multicontact/halfspace: geometric_prefactor needs a value; usage: " +
                       std::string(kUsage));
    gamma = parse_double(args[k + 1], "the geometric prefactor");
    if (!(gamma > 0.0))
      throw InputError("fix multicontact/halfspace: geometric_prefactor must be > 0, got " + args[k + 1]);
  }
  Force& force = *engine.force;
  if (force.multicontact)
    throw InputError("fix multicontact/halfspace: there is already one (" + force.multicontact->owner() +
                     "); a simulation has at most one");
  model_ = std::make_unique<MultiContact>(engine, "fix " + id + " multicontact/halfspace", gamma);
  force.multicontact = model_.get();
}

FixMulticontactHalfspace::~FixMulticontactHalfspace() {
  if (engine_.force && engine_.force->multicontact == model_.get()) engine_.force->multicontact = nullptr;
}

void FixMulticontactHalfspace::unfixed() {
  model_->release();
  if (engine_.force->multicontact == model_.get()) engine_.force->multicontact = nullptr;
}

void FixMulticontactHalfspace::init() {
  const std::string user = "fix " + id + " multicontact/halfspace";
  if (engine_.force->newton_pair)
    throw InputError(user +
                     " needs 'newton off': with newton on the contacts of a ghost particle are "
                     "computed on one rank only and its owner would not record them");
  const GlobalProperty& Y = engine_.modify->require_property("youngsModulus", user);
  const GlobalProperty& nu = engine_.modify->require_property("poissonsRatio", user);
  const int nt = engine_.particles->ntypes;
  std::vector<double> youngs(static_cast<std::size_t>(nt) + 1, 0.0), poisson(youngs.size(), 0.0);
  for (int t = 1; t <= nt; ++t) {
    youngs[t] = Y.per_type(t);
    poisson[t] = nu.per_type(t);
    if (!(youngs[t] > 0.0))
      throw InputError(user + ": youngsModulus of type " + std::to_string(t) + " must be > 0");
  }
  model_->set_materials(std::move(youngs), std::move(poisson));
}

GRANARY_FIX_STYLE("multicontact/halfspace", FixMulticontactHalfspace);

}  // namespace granary
