// fix ID group property/atom NAME scalar|vector restart comm_ghost comm_reverse values...
// (LIGGGHTS): a per-particle property NAME with one value (scalar) or as many
// values as given (vector) per particle, for every particle (the group is
// ignored, as in LIGGGHTS). Particles present when the fix is defined, and
// every particle created later, start with the given values; a property read
// from a restart file keeps its stored values. The set command writes it
// (set ... property/atom NAME values); f_ID (or f_ID[0]) is a scalar property,
// f_ID[1..n] the columns of a vector one. restart = yes|no: written to restart
// files; comm_ghost = yes|no: copied to ghost particles (a style that reads it
// on ghosts sends it every step); comm_reverse is accepted and up to the style
// that uses the property. The values travel with their particle between ranks.
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

bool yes_no(const std::string& w, const std::string& what) {
  if (w == "yes") return true;
  if (w == "no") return false;
  throw InputError(what + " must be yes or no, got '" + w + "'");
}

class FixPropertyAtom : public Fix {
 public:
  FixPropertyAtom(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group property/atom NAME scalar|vector restart(yes|no) comm_ghost(yes|no) "
        "comm_reverse(yes|no) value(s)";
    require_args(args, 9, 1000, usage);
    name_ = args[3];
    const std::string& kind = args[4];
    if (kind != "scalar" && kind != "vector")
      throw InputError("fix " + id + " property/atom: style must be scalar or vector, got '" + kind +
                       "'; usage: " + usage);
    const bool restart = yes_no(args[5], "fix " + id + " property/atom: restart value");
    const bool ghost = yes_no(args[6], "fix " + id + " property/atom: comm_ghost value");
    yes_no(args[7], "fix " + id + " property/atom: comm_reverse value");
    std::vector<double> values;
    for (std::size_t k = 8; k < args.size(); ++k)
      values.push_back(parse_double(args[k], "fix " + id + " property/atom value"));
    if (kind == "scalar" && values.size() != 1)
      throw InputError("fix " + id + " property/atom: a scalar property takes one value, got " +
                       std::to_string(values.size()));
    if (name_.empty() || name_.find('/') != std::string::npos)
      throw InputError("fix " + id + " property/atom: '" + name_ + "' is not a property name (no '/')");
    Particles& p = *engine.particles;
    const bool existed = p.find_field(name_) >= 0 && !p.extras[p.find_field(name_)].data.empty();
    int field;
    try {
      field = p.add_field(name_, static_cast<int>(values.size()), ghost, true);
    } catch (const std::invalid_argument& err) {
      throw InputError("fix " + id + " property/atom: " + err.what());
    }
    ExtraField& f = p.extras[field];
    f.restart = restart;
    f.settable = true;
    f.init = values;
    if (!existed) {
      for (int i = 0; i < p.nlocal; ++i)
        std::copy(values.begin(), values.end(), f.data.begin() + static_cast<std::size_t>(i) * values.size());
    }
    ncomp_ = static_cast<int>(values.size());
    vector_ = kind == "vector";
    peratom_flag = true;
    peratom_cols = vector_ ? ncomp_ : 0;
  }

  unsigned hooks() const override { return 0; }

  void peratom(int col, std::vector<double>& out) override {
    if (!vector_ && col != 0)
      throw InputError("fix " + id + " (property/atom) is a per-atom vector: use f_" + id + " or f_" + id +
                       "[0]");
    if (vector_ && (col < 1 || col > ncomp_))
      throw InputError("fix " + id + " (property/atom) has " + std::to_string(ncomp_) + " columns: use f_" +
                       id + "[1.." + std::to_string(ncomp_) + "]");
    const Particles& p = *engine_.particles;
    const FieldRef ref(p, name_.c_str());
    const double* d = ref.data(p);
    out.assign(p.nlocal, 0.0);
    const int c = vector_ ? col - 1 : 0;
    for (int i = 0; i < p.nlocal && d; ++i)
      out[i] = d[static_cast<std::size_t>(i) * ncomp_ + c];
  }

  void unfixed() override { engine_.particles->release_field(name_); }

 private:
  std::string name_;
  int ncomp_ = 1;
  bool vector_ = false;
};

}  // namespace

GRANARY_FIX_STYLE("property/atom", FixPropertyAtom);

}  // namespace granary
