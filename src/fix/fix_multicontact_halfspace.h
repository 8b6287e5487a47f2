// fix ID group multicontact/halfspace [geometric_prefactor GAMMA]: switches
// on the multiple-contact model (pair/multicontact.h) for the contacts of
// pair styles and walls with "surface multicontact"; see
// doc/fixes/multicontact_halfspace.md.
#pragma once

#include <memory>

#include "fix/fix.h"
#include "pair/multicontact.h"

namespace granary {

class FixMulticontactHalfspace : public Fix {
 public:
  FixMulticontactHalfspace(Engine& engine, const Args& args);
  ~FixMulticontactHalfspace() override;
  unsigned hooks() const override { return 0; }
  void init() override;
  void unfixed() override;

 private:
  std::unique_ptr<MultiContact> model_;
};

}  // namespace granary
