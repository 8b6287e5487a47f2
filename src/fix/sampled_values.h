// Values sampled by the time-averaging fixes (ave/atom, ave/histo): per-atom
// inputs (particle attributes, c_ID / f_ID per-atom vectors or array columns,
// atom-style variables), and the sampling steps of a Nevery/Nrepeat/Nfreq
// schedule.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace granary {

class Engine;
class Fix;

/// One input: a particle attribute (x y z vx vy vz fx fy fz), c_ID, c_ID[i],
/// f_ID, f_ID[i] or v_name.
struct SampledValue {
  char kind = 'a';  // 'a' (attribute), 'c', 'f' or 'v'
  std::string id;   // attribute, compute/fix ID or variable name
  int col = 0;      // 0: scalar or vector, i >= 1: element or column i
  std::string text;
};

/// Parse one input word; `what` names the fix in errors, `usage` ends them.
SampledValue parse_sampled_value(const std::string& word, const std::string& what, const std::string& usage);

/// Check at init that a per-atom input exists and gives per-atom values of the
/// right shape (`self` may not be averaged by itself).
void check_peratom_value(Engine& engine, const SampledValue& v, const Fix* self, const std::string& what);

/// Columns of a per-atom compute or fix (0: a per-atom vector).
int peratom_columns(Engine& engine, const SampledValue& v);

/// Check at init that a global input (c_ID, c_ID[i], f_ID, f_ID[i], v_name of
/// an equal-style variable) exists; `atom_hint` ends the error for an
/// atom-style variable.
void check_global_value(Engine& engine, const SampledValue& v, const Fix* self, const std::string& what,
                        const std::string& atom_hint);

/// The current value of a global input.
double sample_global(Engine& engine, const SampledValue& v);

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f) std::fclose(f);
  }
};
/// An output file that closes itself.
using OutputFile = std::unique_ptr<std::FILE, FileCloser>;

/// Start an output file on rank 0 with `header` (the file is replaced as a
/// whole) and, with `keep_open`, open it for appending (nullptr elsewhere);
/// every rank stops with an error naming `what` when it cannot be written.
OutputFile start_output_file(Engine& engine, const std::string& path, const std::string& header,
                             bool keep_open, const std::string& what);

/// Rank 0: add `block` to an output file opened by start_output_file, or
/// with `overwrite` replace the file by `header` + `block`.
void write_output_block(const std::string& path, const std::string& header, const std::string& block,
                        bool overwrite, const OutputFile& fp, const std::string& what);

/// Per-atom values of the local particles (nlocal entries).
void sample_peratom(Engine& engine, const SampledValue& v, std::vector<double>& out);

/// The sampling steps of a Nevery/Nrepeat/Nfreq average: windows of Nrepeat
/// samples Nevery steps apart, each ending on a multiple of Nfreq.
class SamplingSchedule {
 public:
  void set(long long every, long long nrepeat, long long nfreq, long long start = 0) {
    every_ = every;
    nrepeat_ = nrepeat;
    nfreq_ = nfreq;
    start_ = start;
  }
  /// Start afresh: the first whole window at or after step `now` (and `start`).
  void begin(std::int64_t now);
  /// Before a run: a run that starts after the next sampling step (e.g. after
  /// reset_timestep) starts a new window.
  void catch_up(std::int64_t now) {
    if (next_ < now) begin(now);
  }
  bool due(std::int64_t step) const { return step == next_; }
  /// Whether the next sample is the first of its window.
  bool window_start() const { return taken_ == 0; }
  /// Record the sample of `step`; true when it completes its window (an output step).
  bool sampled(std::int64_t step);

 private:
  long long every_ = 1, nrepeat_ = 1, nfreq_ = 1, start_ = 0;
  std::int64_t next_ = 0;  // next sampling step
  long long taken_ = 0;    // samples taken in the current window
};

/// The value of the keyword `ave` at words[k]: 0 for `one`, 1 for `running`,
/// 2 for `window M` (M read from words[k + 1] into `window`, and k moved onto
/// it); `what` names the fix in errors.
int parse_ave_keyword(const std::vector<std::string>& words, std::size_t& k, const std::string& what,
                      long long& window);

/// Read Nevery, Nrepeat and Nfreq from words[0..2] and check them as LIGGGHTS
/// states them (positive, Nfreq a multiple of Nevery, (Nrepeat-1)*Nevery < Nfreq).
void parse_schedule(const std::string* words, const std::string& what, long long& every, long long& nrepeat,
                    long long& nfreq);

}  // namespace granary
