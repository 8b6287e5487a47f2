// compute ID group-ID slice NSTART NSTOP NSKIP INPUT
// (LAMMPS/LIGGGHTS syntax): elements NSTART, NSTART + NSKIP, ... up to NSTOP
// (1-based, inclusive) of the global vector INPUT (c_ID or f_ID), as a global
// vector. The group is ignored. See doc/computes/slice.md.
#include <string>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/utils.h"
#include "fix/fix.h"

namespace granary {

namespace {

const char* kUsage = "compute ID group-ID slice NSTART NSTOP NSKIP c_ID|f_ID";

class ComputeSlice : public Compute {
 public:
  ComputeSlice(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string where = "compute " + id + " slice";
    if (args.size() < 7) throw InputError(where + ": wrong number of arguments; usage: " + kUsage);
    if (args.size() > 7)
      throw InputError(where +
                       ": one input per compute slice (Granary has no global arrays); define one slice "
                       "per input");
    start_ = parse_int(args[3], where + " NSTART");
    stop_ = parse_int(args[4], where + " NSTOP");
    skip_ = parse_int(args[5], where + " NSKIP");
    if (start_ < 1 || stop_ < start_ || skip_ < 1)
      throw InputError(where + ": needs 1 <= NSTART <= NSTOP and NSKIP >= 1, got " + args[3] + " " + args[4] +
                       " " + args[5]);
    const std::string& in = args[6];
    if ((in.rfind("c_", 0) != 0 && in.rfind("f_", 0) != 0) || in.size() < 3)
      throw InputError(where + ": the input '" + in + "' must be c_ID or f_ID (a global vector)");
    if (in.find('[') != std::string::npos)
      throw InputError(where + ": '" + in +
                       "' is a column of a global array; Granary's computes and fixes give "
                       "global vectors: use c_ID or f_ID");
    if ((stop_ - start_) / skip_ >= 100000000LL)
      throw InputError(where + ": more than 1e8 values; take a smaller range or a larger NSKIP");
    compute_ = in[0] == 'c';
    input_ = in.substr(2);
    size_vector = static_cast<int>((stop_ - start_) / skip_ + 1);
  }

  void init() override {
    const std::string where = "compute " + id + " slice";
    const int n = input_size(where);
    if (n == 0)
      throw InputError(where + ": " + std::string(compute_ ? "compute " : "fix ") + input_ +
                       " gives no global vector");
  }

  void compute_vector() override {
    const std::string where = "compute " + id + " slice";
    const int n = input_size(where);
    if (stop_ > n)
      throw InputError(where + ": NSTOP " + std::to_string(stop_) + " is beyond the " + std::to_string(n) +
                       " values of " + (compute_ ? "c_" : "f_") + input_);
    vector.clear();
    for (long long k = start_; k <= stop_; k += skip_)
      vector.push_back(compute_ ? engine_.compute_value(input_, static_cast<int>(k))
                                : engine_.fix_value(input_, static_cast<int>(k)));
  }

 private:
  int input_size(const std::string& where) const {
    if (compute_) return engine_.modify->compute_or_error(input_, where)->size_vector;
    return engine_.modify->fix_or_error(input_, where)->size_vector;
  }

  long long start_ = 1, stop_ = 1, skip_ = 1;
  bool compute_ = true;
  std::string input_;
};

}  // namespace

GRANARY_COMPUTE_STYLE("slice", ComputeSlice);

}  // namespace granary
