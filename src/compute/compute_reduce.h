// compute reduce and compute reduce/region: reduce per-atom values of the
// group's particles (optionally only those in a region) to global numbers.
//
//   compute ID group reduce MODE input1 input2 ... [replace V1 V2]
//   compute ID group reduce/region REGION MODE input1 input2 ... [replace V1 V2]
//
// MODE: sum, min, max, ave, sumsq, avesq, sumabs, aveabs. Inputs: a particle
// property (x, vx, fx, omegax, radius, mass, ...), c_ID, c_ID[i], f_ID, f_ID[i],
// v_name (atom-style variable); c_ID[*] / f_ID[*] expand to every column.
// One input gives a global scalar, several a global vector.
#pragma once

#include <string>
#include <vector>

#include "compute/compute.h"

namespace granary {

class Region;

class ComputeReduce : public Compute {
 public:
  ComputeReduce(Engine& engine, const Args& args);

  void init() override;
  double compute_scalar() override;
  void compute_vector() override;

 protected:
  /// `region_style`: args carry a region ID before the mode (reduce/region).
  ComputeReduce(Engine& engine, const Args& args, bool region_style);

 private:
  enum class Mode { Sum, Min, Max, Ave, SumSq, AveSq, SumAbs, AveAbs };
  struct Input {
    enum Kind { Atom, ComputeValue, FixValue, Variable } kind = Atom;
    std::string name;  // property, compute/fix ID or variable name
    int col = 0;       // 0: per-atom vector; >= 1: array column
    std::string text;  // as written, for messages
  };

  void parse(const Args& args, std::size_t first);
  void add_input(const std::string& word);
  void check_input(const Input& in) const;
  const Region* region() const;
  /// Per-atom values of one input for the local particles.
  void values(const Input& in, std::vector<double>& out);
  /// Reduce every input (collective); fills `out` with one number per input.
  void reduce_all(std::vector<double>& out);

  Mode mode_ = Mode::Sum;
  std::string region_id_;  // empty: no region
  std::vector<Input> inputs_;
  std::vector<int> replace_;  // replace_[m] = input whose extreme picks the particle, or -1
};

}  // namespace granary
