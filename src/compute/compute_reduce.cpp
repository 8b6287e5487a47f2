// compute reduce: see compute_reduce.h.
#include "compute/compute_reduce.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/registry.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "core/modify.h"
#include "particles/particles.h"

namespace granary {

namespace {
constexpr double kBig = 1.0e20;  // value of min/max over no particles (as LAMMPS)
}  // namespace

ComputeReduce::ComputeReduce(Engine& engine, const Args& args) : ComputeReduce(engine, args, false) {}

ComputeReduce::ComputeReduce(Engine& engine, const Args& args, bool region_style) : Compute(engine, args) {
  std::size_t k = 3;
  if (region_style) {
    if (args.size() < 4) {
      throw InputError("usage: compute ID group-ID reduce/region REGION MODE input ... [replace V1 V2]");
    }
    region_id_ = args[3];
    engine.domain->region_or_error(region_id_, "compute " + id);
    k = 4;
  }
  parse(args, k);
}

void ComputeReduce::parse(const Args& args, std::size_t first) {
  const std::string usage = "compute ID group-ID " + style + (region_id_.empty() ? "" : " REGION") +
                            " sum|min|max|ave|sumsq|avesq|sumabs|aveabs input ... [replace V1 V2]";
  if (args.size() < first + 2)
    throw InputError("compute " + style + " needs a mode and at least one input; usage: " + usage);
  const std::string& m = args[first];
  if (m == "sum")
    mode_ = Mode::Sum;
  else if (m == "min")
    mode_ = Mode::Min;
  else if (m == "max")
    mode_ = Mode::Max;
  else if (m == "ave")
    mode_ = Mode::Ave;
  else if (m == "sumsq")
    mode_ = Mode::SumSq;
  else if (m == "avesq")
    mode_ = Mode::AveSq;
  else if (m == "sumabs")
    mode_ = Mode::SumAbs;
  else if (m == "aveabs")
    mode_ = Mode::AveAbs;
  else {
    const std::string hint =
        did_you_mean(m, {"sum", "min", "max", "ave", "sumsq", "avesq", "sumabs", "aveabs"});
    throw InputError("unknown compute " + style + " mode '" + m + "'" + (hint.empty() ? "" : "; " + hint) +
                     "; usage: " + usage);
  }
  std::size_t k = first + 1;
  for (; k < args.size() && args[k] != "replace"; ++k)
    add_input(args[k]);
  if (inputs_.empty()) throw InputError("compute " + style + " needs at least one input; usage: " + usage);
  replace_.assign(inputs_.size(), -1);
  while (k < args.size()) {
    if (args[k] != "replace")
      throw InputError("unknown compute " + style + " keyword '" + args[k] + "'; usage: " + usage);
    if (k + 2 >= args.size()) throw InputError("compute " + style + " replace needs two input numbers V1 V2");
    if (mode_ != Mode::Min && mode_ != Mode::Max)
      throw InputError("compute " + style + " replace works only with min or max");
    const long long a = parse_int(args[k + 1], "replace V1"), b = parse_int(args[k + 2], "replace V2");
    const long long n = static_cast<long long>(inputs_.size());
    if (a < 1 || a > n || b < 1 || b > n || a == b) {
      throw InputError("compute " + style + " replace needs two different input numbers in 1.." +
                       std::to_string(n));
    }
    if (replace_[b - 1] >= 0)
      throw InputError("compute " + style + " replace: input " + std::to_string(b) + " is replaced itself");
    replace_[a - 1] = static_cast<int>(b - 1);
    k += 3;
  }
  for (std::size_t i = 0; i < replace_.size(); ++i) {
    if (replace_[i] >= 0 && replace_[replace_[i]] >= 0) {
      throw InputError("compute " + style + " replace: chained replacements are not allowed");
    }
  }
  const std::size_t n = inputs_.size();
  scalar_flag = n == 1;
  size_vector = n == 1 ? 0 : static_cast<int>(n);
  vector.assign(n > 1 ? n : 0, 0.0);
  extensive = mode_ == Mode::Sum || mode_ == Mode::SumSq || mode_ == Mode::SumAbs;
}

void ComputeReduce::add_input(const std::string& word) {
  Input in;
  in.text = word;
  const bool cf = word.rfind("c_", 0) == 0 || word.rfind("f_", 0) == 0;
  if (cf) {
    in.kind = word[0] == 'c' ? Input::ComputeValue : Input::FixValue;
    std::string rest = word.substr(2);
    const auto open = rest.find('[');
    bool all_columns = false;
    if (open != std::string::npos) {
      if (rest.back() != ']')
        throw InputError("bad input '" + word + "' in compute " + id + "; write c_ID[i]");
      const std::string idx = rest.substr(open + 1, rest.size() - open - 2);
      rest = rest.substr(0, open);
      if (idx == "*") {
        all_columns = true;
      } else {
        in.col = static_cast<int>(parse_int(idx, "the column of " + word));
        // [0] is the per-atom vector itself (LIGGGHTS' f_Temp[0] of a property/atom)
        if (in.col < 0) throw InputError("columns are numbered from 1 in '" + word + "' (0: the vector)");
      }
    }
    in.name = rest;
    if (all_columns) {
      int ncols = 0;
      if (in.kind == Input::ComputeValue) {
        const Compute* c = engine_.modify->compute_or_error(in.name, "compute " + id);
        ncols = c->peratom_flag ? c->peratom_cols : 0;
      } else {
        const Fix* f = engine_.modify->fix_or_error(in.name, "compute " + id);
        ncols = f->peratom_flag ? f->peratom_cols : 0;
      }
      if (ncols == 0) throw InputError("'" + word + "' in compute " + id + " needs a per-atom array");
      for (int c = 1; c <= ncols; ++c) {
        Input one = in;
        one.col = c;
        one.text = word.substr(0, 2) + in.name + "[" + std::to_string(c) + "]";
        check_input(one);
        inputs_.push_back(one);
      }
      return;
    }
  } else if (word.rfind("v_", 0) == 0) {
    in.kind = Input::Variable;
    in.name = word.substr(2);
  } else {
    in.kind = Input::Atom;
    in.name = word;
  }
  check_input(in);
  inputs_.push_back(in);
}

void ComputeReduce::check_input(const Input& in) const {
  const std::string where = "compute " + id;
  switch (in.kind) {
    case Input::Atom: {
      std::vector<double> probe;
      if (!engine_.atom_vector(in.name, probe)) {
        throw InputError(
            "unknown input '" + in.text + "' in " + where +
            "; use a particle property (x, vx, fx, omegax, radius, mass, ...), c_ID, f_ID or v_name");
      }
      break;
    }
    case Input::ComputeValue: {
      const Compute* c = engine_.modify->compute_or_error(in.name, where);
      if (c == this) throw InputError(where + " cannot reduce its own values");
      if (!c->peratom_flag)
        throw InputError("compute " + in.name + " in " + where + " does not give per-atom values");
      if (in.col == 0 && c->peratom_cols != 0) {
        throw InputError("compute " + in.name + " gives a per-atom array; write c_" + in.name + "[i] in " +
                         where);
      }
      if (in.col > 0 && in.col > c->peratom_cols) {
        throw InputError("'" + in.text + "' in " + where + ": compute " + in.name + " has " +
                         std::to_string(c->peratom_cols) + " per-atom columns");
      }
      break;
    }
    case Input::FixValue: {
      const Fix* f = engine_.modify->fix_or_error(in.name, where);
      if (!f->peratom_flag)
        throw InputError("fix " + in.name + " in " + where + " does not give per-atom values");
      if (in.col == 0 && f->peratom_cols != 0) {
        throw InputError("fix " + in.name + " gives a per-atom array; write f_" + in.name + "[i] in " +
                         where);
      }
      if (in.col > 0 && in.col > f->peratom_cols) {
        throw InputError("'" + in.text + "' in " + where + ": fix " + in.name + " has " +
                         std::to_string(f->peratom_cols) + " per-atom columns");
      }
      break;
    }
    case Input::Variable:
      if (!engine_.input->variables().find(in.name)) {
        throw InputError("unknown variable '" + in.name + "' in " + where + "; define it with variable " +
                         in.name + " atom ...");
      }
      break;
  }
}

void ComputeReduce::init() {
  for (const Input& in : inputs_)
    check_input(in);
  region();
}

const Region* ComputeReduce::region() const {
  if (region_id_.empty()) return nullptr;
  return engine_.domain->region_or_error(region_id_, "compute " + id);
}

void ComputeReduce::values(const Input& in, std::vector<double>& out) {
  switch (in.kind) {
    case Input::Atom:
      engine_.atom_vector(in.name, out);
      break;
    case Input::ComputeValue:
      engine_.compute_peratom(in.name, in.col, out);
      break;
    case Input::FixValue:
      engine_.fix_peratom(in.name, in.col, out);
      break;
    case Input::Variable:
      engine_.input->variables().compute_atom(in.name, out);
      break;
  }
  out.resize(engine_.particles->nlocal, 0.0);
}

void ComputeReduce::reduce_all(std::vector<double>& out) {
  const Particles& p = *engine_.particles;
  const int n = p.nlocal;
  const Region* reg = region();
  std::vector<int> chosen;
  for (int i = 0; i < n; ++i)
    if ((p.mask[i] & groupbit) && (!reg || reg->match(p.x[i]))) chosen.push_back(i);

  const std::size_t m = inputs_.size();
  std::vector<std::vector<double>> vals(m);
  for (std::size_t k = 0; k < m; ++k)
    values(inputs_[k], vals[k]);
  out.assign(m, 0.0);

  if (mode_ == Mode::Min || mode_ == Mode::Max) {
    const bool is_min = mode_ == Mode::Min;
    struct ValueRank {  // layout of MPI_DOUBLE_INT
      double value;
      int rank;
    };
    std::vector<ValueRank> local(m), global(m);
    std::vector<int> where(m, -1);  // local index of this rank's extreme
    for (std::size_t k = 0; k < m; ++k) {
      double best = is_min ? kBig : -kBig;
      for (int i : chosen) {
        const double v = vals[k][i];
        if (is_min ? v < best : v > best) {
          best = v;
          where[k] = i;
        }
      }
      local[k] = {best, engine_.rank};
    }
    MPI_Allreduce(local.data(), global.data(), static_cast<int>(m), MPI_DOUBLE_INT,
                  is_min ? MPI_MINLOC : MPI_MAXLOC, engine_.world);
    for (std::size_t k = 0; k < m; ++k)
      out[k] = global[k].value;
    // replace: the value of input k at the particle where input replace_[k] is extreme
    for (std::size_t k = 0; k < m; ++k) {
      const int j = replace_[k];
      if (j < 0) continue;
      const int owner = global[j].rank;
      double v = out[k];
      if (engine_.rank == owner && where[j] >= 0) v = vals[k][where[j]];
      MPI_Bcast(&v, 1, MPI_DOUBLE, owner, engine_.world);
      out[k] = v;
    }
    return;
  }

  // sums (with a trailing count for the averages)
  std::vector<double> local(m + 1, 0.0), global(m + 1, 0.0);
  for (std::size_t k = 0; k < m; ++k) {
    double s = 0.0;
    for (int i : chosen) {
      const double v = vals[k][i];
      if (mode_ == Mode::SumSq || mode_ == Mode::AveSq)
        s += v * v;
      else if (mode_ == Mode::SumAbs || mode_ == Mode::AveAbs)
        s += std::fabs(v);
      else
        s += v;
    }
    local[k] = s;
  }
  local[m] = static_cast<double>(chosen.size());
  MPI_Allreduce(local.data(), global.data(), static_cast<int>(m + 1), MPI_DOUBLE, MPI_SUM, engine_.world);
  const bool average = mode_ == Mode::Ave || mode_ == Mode::AveSq || mode_ == Mode::AveAbs;
  for (std::size_t k = 0; k < m; ++k) {
    out[k] = global[k];
    if (average) out[k] = global[m] > 0.0 ? global[k] / global[m] : 0.0;
  }
}

double ComputeReduce::compute_scalar() {
  std::vector<double> out;
  reduce_all(out);
  scalar = out[0];
  return scalar;
}

void ComputeReduce::compute_vector() {
  reduce_all(vector);
}

GRANARY_COMPUTE_STYLE("reduce", ComputeReduce);

}  // namespace granary
