// fix ID group particledistribution/discrete SEED N T1 W1 ... TN WN [fractions mass|number|volume]
// (also particledistribution/discrete/massbased and .../numberbased)
//
// A discrete mixture of particle templates (LIGGGHTS syntax). The weights are
// mass fractions by default, as in LIGGGHTS; `fractions number` makes them
// number fractions and `fractions volume` solid-volume fractions (Granary
// additions). Whatever their meaning, they are turned into the probability
// that one drawn particle comes from each template (the effective number
// probabilities). Draws use a generator seeded by SEED that advances the same
// way on every rank, so every rank draws the same particles.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "fix/fix_particle_template.h"

namespace granary {

class FixParticleDistributionDiscrete : public Fix {
 public:
  enum class Fractions { Mass, Number, Volume };

  /// One drawn particle with the group bits of its template and of this distribution.
  struct Drawn {
    TemplateParticle particle;
    int groupbits = 1;
    int template_index = 0;
  };

  FixParticleDistributionDiscrete(Engine& engine, const Args& args);
  unsigned hooks() const override { return 0; }
  void init() override;

  /// A random particle: template chosen by the effective number probabilities.
  TemplateParticle draw();
  /// Index of a random template (by the effective number probabilities).
  int draw_template();
  /// n particles. exact: the count of each template is n times its probability,
  /// rounded so that they sum to n (the remainders go to randomly chosen
  /// templates), largest templates first; otherwise n independent draws.
  std::vector<Drawn> draw_batch(long long n, bool exact);

  int ntemplates() const { return static_cast<int>(template_ids_.size()); }
  const std::string& template_id(int i) const { return template_ids_[i]; }
  /// The template fix (looked up by ID, so a redefined template is seen); error when gone.
  FixParticleTemplate& templ(int i) const;
  /// Weights as given, normalised to sum 1.
  const std::vector<double>& weights() const { return weights_; }
  Fractions fractions() const { return fractions_; }
  /// Probability that a drawn particle comes from template i.
  std::vector<double> number_probabilities() const;
  /// Expected solid volume and mass of one drawn particle.
  double mean_volume() const;
  double mean_mass() const;
  /// Largest bounding radius of any template.
  double max_bounding_radius() const;
  /// True when any template makes multisphere particles.
  bool any_multisphere() const;

  void pack_restart(std::string& out) const override;
  void unpack_restart(const std::string& in) override;

 private:
  std::vector<std::string> template_ids_;
  std::vector<double> weights_;
  Fractions fractions_ = Fractions::Mass;
  std::mt19937_64 gen_;
};

}  // namespace granary
