#include "fix/sampled_values.h"

#include <algorithm>

#include <mpi.h>

#include "compute/compute.h"
#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/modify.h"
#include "core/utils.h"
#include "core/variable.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

SampledValue parse_sampled_value(const std::string& w, const std::string& what, const std::string& usage) {
  static const char* const kAttributes[] = {"x", "y", "z", "vx", "vy", "vz", "fx", "fy", "fz"};
  for (const char* a : kAttributes)
    if (w == a) return SampledValue{'a', w, 0, w};
  const bool ref = w.size() > 2 && w[1] == '_' && (w[0] == 'c' || w[0] == 'f' || w[0] == 'v');
  if (!ref) throw InputError(what + ": unknown value '" + w + "'; usage: " + usage);
  SampledValue v{w[0], w.substr(2), 0, w};
  const auto lb = v.id.find('[');
  if (lb != std::string::npos) {
    if (v.kind == 'v' || v.id.back() != ']' || lb == 0)
      throw InputError(what + ": value '" + w + "' is malformed; use c_ID, c_ID[i], f_ID, f_ID[i] or v_name");
    v.col = static_cast<int>(parse_int(v.id.substr(lb + 1, v.id.size() - lb - 2), what + " index of " + w));
    // [0] is the per-atom vector itself (LIGGGHTS' f_Temp[0] of a property/atom)
    if (v.col < 0) throw InputError(what + ": the index in '" + w + "' must be >= 1 (or 0 for a vector)");
    v.id.resize(lb);
  }
  return v;
}

int peratom_columns(Engine& engine, const SampledValue& v) {
  if (v.kind == 'c') return engine.modify->compute_or_error(v.id, v.text)->peratom_cols;
  if (v.kind == 'f') return engine.modify->fix_or_error(v.id, v.text)->peratom_cols;
  return 0;
}

void check_peratom_value(Engine& engine, const SampledValue& v, const Fix* self, const std::string& what) {
  int cols = 0;
  if (v.kind == 'c') {
    const Compute* c = engine.modify->compute_or_error(v.id, what + " " + v.text);
    if (!c->peratom_flag)
      throw InputError(what + ": compute " + v.id + " gives no per-atom values; " + v.text +
                       " needs a per-atom compute");
    cols = c->peratom_cols;
  } else if (v.kind == 'f') {
    const Fix* f = engine.modify->fix_or_error(v.id, what + " " + v.text);
    if (f == self) throw InputError(what + " cannot use its own output");
    if (!f->peratom_flag)
      throw InputError(what + ": fix " + v.id + " gives no per-atom values; " + v.text +
                       " needs a fix with per-atom output");
    cols = f->peratom_cols;
  } else if (v.kind == 'v') {
    if (!engine.input->variables().find(v.id))
      throw InputError(what + ": variable '" + v.id + "' does not exist");
    if (!engine.input->variables().is_atom(v.id))
      throw InputError(what + ": variable '" + v.id + "' must be atom-style (a value per particle)");
    return;
  } else {
    return;
  }
  if (v.col == 0 && cols != 0)
    throw InputError(what + ": " + v.text + " is a per-atom array of " + std::to_string(cols) +
                     " columns; give a column " + v.text + "[i]");
  if (v.col > 0 && (cols == 0 || v.col > cols))
    throw InputError(
        what + ": " + v.text + " has no column " + std::to_string(v.col) + " (" +
        (cols == 0 ? std::string("it is a per-atom vector") : std::to_string(cols) + " columns") + ")");
}

void check_global_value(Engine& engine, const SampledValue& v, const Fix* self, const std::string& what,
                        const std::string& atom_hint) {
  if (v.kind == 'c') {
    engine.modify->compute_or_error(v.id, what + " " + v.text);
  } else if (v.kind == 'f') {
    if (engine.modify->fix_or_error(v.id, what + " " + v.text) == self)
      throw InputError(what + " cannot use its own output");
  } else if (!engine.input->variables().find(v.id)) {
    throw InputError(what + ": variable '" + v.id + "' does not exist");
  } else if (engine.input->variables().is_atom(v.id)) {
    throw InputError(what + ": variable '" + v.id + "' is atom-style; " + atom_hint);
  }
}

double sample_global(Engine& engine, const SampledValue& v) {
  if (v.kind == 'c') return engine.compute_value(v.id, v.col);
  if (v.kind == 'f') return engine.fix_value(v.id, v.col);
  return engine.input->variables().compute_equal(v.id);
}

OutputFile start_output_file(Engine& engine, const std::string& path, const std::string& header,
                             bool keep_open, const std::string& what) {
  std::string err;
  std::FILE* fp = nullptr;
  if (engine.rank == 0) {
    // the header replaces the file as a whole (a temporary file, renamed);
    // output is then appended and flushed
    err = replace_file(path, header);
    if (err.empty() && keep_open) fp = std::fopen(path.c_str(), "a");
    if (err.empty() && keep_open && !fp) err = "cannot open '" + path + "' for writing";
  }
  int ok = err.empty() ? 1 : 0;
  MPI_Bcast(&ok, 1, MPI_INT, 0, engine.world);  // rank 0 writes; every rank stops together
  if (!ok) {
    throw InputError(what + ": " + (err.empty() ? "cannot write '" + path + "'" : err) +
                     "; check that the directory exists and is writable");
  }
  return OutputFile(fp);
}

void sample_peratom(Engine& engine, const SampledValue& v, std::vector<double>& out) {
  if (v.kind == 'a')
    engine.atom_vector(v.id, out);
  else if (v.kind == 'c')
    engine.compute_peratom(v.id, v.col, out);
  else if (v.kind == 'f')
    engine.fix_peratom(v.id, v.col, out);
  else
    engine.input->variables().compute_atom(v.id, out);
  out.resize(engine.particles->nlocal, 0.0);
}

void SamplingSchedule::begin(std::int64_t now) {
  now = std::max<std::int64_t>(now, start_);
  std::int64_t nv = (now / nfreq_) * nfreq_;
  if (nv < now) nv += nfreq_;
  nv -= (nrepeat_ - 1) * every_;
  if (nv < now) nv += nfreq_;
  next_ = nv;
  taken_ = 0;
}

bool SamplingSchedule::sampled(std::int64_t step) {
  ++taken_;
  if (taken_ < nrepeat_) {
    next_ += every_;
    return false;
  }
  taken_ = 0;
  next_ = step + nfreq_ - (nrepeat_ - 1) * every_;
  return true;
}

void write_output_block(const std::string& path, const std::string& header, const std::string& block,
                        bool overwrite, const OutputFile& fp, const std::string& what) {
  if (overwrite) {
    const std::string err = replace_file(path, header + block);
    if (!err.empty()) throw InputError(what + ": " + err);
  } else if (fp) {
    std::fputs(block.c_str(), fp.get());
    std::fflush(fp.get());
  }
}

int parse_ave_keyword(const std::vector<std::string>& words, std::size_t& k, const std::string& what,
                      long long& window) {
  const std::string& val = words[k];
  if (val == "one") return 0;
  if (val == "running") return 1;
  if (val == "window") {
    if (k + 1 >= words.size()) throw InputError(what + ": ave window needs the number of outputs M");
    window = parse_int(words[++k], what + " ave window M");
    if (window <= 0) throw InputError(what + ": ave window M must be positive");
    return 2;
  }
  throw InputError(what + ": ave must be one, running or window M (got '" + val + "')");
}

void parse_schedule(const std::string* words, const std::string& what, long long& every, long long& nrepeat,
                    long long& nfreq) {
  every = parse_int(words[0], what + " Nevery");
  nrepeat = parse_int(words[1], what + " Nrepeat");
  nfreq = parse_int(words[2], what + " Nfreq");
  if (every <= 0 || nrepeat <= 0 || nfreq <= 0)
    throw InputError(what + ": Nevery, Nrepeat and Nfreq must be positive (got " + std::to_string(every) +
                     " " + std::to_string(nrepeat) + " " + std::to_string(nfreq) + ")");
  if (nfreq % every != 0)
    throw InputError(what + ": Nfreq (" + std::to_string(nfreq) + ") must be a multiple of Nevery (" +
                     std::to_string(every) + ")");
  if ((nrepeat - 1) * every >= nfreq)
    throw InputError(what + ": the samples of one average must not reach into the previous one: " +
                     "(Nrepeat-1)*Nevery = " + std::to_string((nrepeat - 1) * every) +
                     " must be less than Nfreq (" + std::to_string(nfreq) + ")");
}

}  // namespace granary
