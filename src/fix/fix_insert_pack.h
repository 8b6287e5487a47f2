// fix ID group insert/pack seed SEED distributiontemplate DIST [general keywords]
//     region REGION volumefraction_region PHI | particles_in_region N | mass_in_region M [ntry_mc N]
//
// Fills a region up to a target volume fraction, particle count or mass at
// each insertion step; the insertion itself is FixInsert's (fix_insert.h).
#pragma once

#include "fix/fix_insert.h"

namespace granary {

class FixInsertPack : public FixInsert {
 public:
  FixInsertPack(Engine& engine, const Args& args);
  void init() override;

 protected:
  long long count_to_insert() override;
  void inserted_batch(const Result& r) override;

 private:
  enum class Target { VolumeFraction, Particles, Mass } target_ = Target::VolumeFraction;
  double target_value_ = 0.0;
  // existing particles at the last insertion step
  double existing_number_ = 0.0, existing_mass_ = 0.0, existing_volume_ = 0.0;
  long long requested_ = 0;
};

}  // namespace granary
