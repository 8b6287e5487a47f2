// fix ID group insert/rate/region seed SEED distributiontemplate DIST
//     nparticles N|INF | mass M|INF  particlerate R | massrate MR  insert_every STEPS
//     [general keywords of insert/pack] region REGION [ntry_mc N]
//
// Inserts particles into a region at a steady rate (LIGGGHTS syntax): every
// STEPS steps a batch of R * STEPS * dt particles (fractions carried over to
// the next batch, so the count after k batches is floor(k R STEPS dt)), until
// N particles (or the number expected for mass M) are in. Placement, overlap
// checks, ids and rank independence are those of FixInsert (fix_insert.h).
#pragma once

#include <map>
#include <string>

#include "fix/fix_insert.h"

namespace granary {

class FixInsertRateRegion : public FixInsert {
 public:
  FixInsertRateRegion(Engine& engine, const Args& args);
  void init() override;
  void pack_restart(std::string& out) const override;
  void unpack_restart(const std::string& in) override;

  /// Particles to insert in all (-1: no limit).
  long long target() const { return target_n_; }

 protected:
  /// For styles that share the amount and rate keywords (insert/stream): the
  /// style's own keywords are added to nparticles, mass, particlerate and
  /// massrate; `stream` builds its own insertion volume (no region) and may
  /// derive insert_every itself (then it must set insert_every_ before the run).
  FixInsertRateRegion(Engine& engine, const Args& args, std::map<std::string, int> style_keywords,
                      const std::string& usage, bool stream);

  long long count_to_insert() override;
  void inserted_batch(const Result& r) override;
  bool done_after_insertion() const override { return target_n_ >= 0 && ninserted_ >= target_n_; }

 protected:
  bool insert_every_given_ = false;  // insert_every appeared in the command

 private:
  bool by_mass_ = false;        // mass M instead of nparticles N
  double target_value_ = -1.0;  // N or M; < 0 for INF
  long long target_n_ = -1;     // particles to insert in all; -1 for INF
  bool rate_by_mass_ = false;   // massrate instead of particlerate
  double rate_ = 0.0;           // particles/s or kg/s
  double carry_ = 0.0;          // fraction of a particle carried to the next batch
};

}  // namespace granary
