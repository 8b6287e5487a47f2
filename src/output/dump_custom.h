// `dump ID group custom N file fields...`: LAMMPS text dump format.
//
// Also holds what the custom and custom/vtk styles share: the per-particle
// field list (parsing, checks, packing of the selected particles), the gather
// of packed rows to rank 0, file-name expansion and collective error reporting.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "core/utils.h"
#include "output/dump.h"

namespace granary {

struct AtomProperty;

/// One output column of a custom-style dump.
struct DumpField {
  enum Source { kCore, kCompute, kFix, kVariable };
  std::string name;  // as written in the command: "vx", "c_stress[2]", "v_ke"
  Source source = kCore;
  const AtomProperty* property = nullptr;  // kCore: the per-particle property (core/atom_properties.h)
  std::string ref;                         // compute, fix or variable name
  int col = 0;                             // c_/f_: 0 = per-atom vector, i >= 1 = column i
  bool integer = false;                    // an integer quantity (id, type, image flags, body)
};

/// The field list of a custom-style dump.
class DumpFields {
 public:
  /// Parse `words` (field names); `what` names the command in messages.
  /// c_ID[*] and f_ID[*] expand to every column of an existing compute or fix.
  DumpFields(Engine& engine, const Args& words, const std::string& what);

  /// Check that computes, fixes and variables exist and give per-atom values.
  void init();
  /// Owned particles in the group (and in the region, when not empty).
  void select(int groupbit, const std::string& region, std::vector<int>& out) const;
  /// Row-major values of the selected particles: out[k * ncols() + c], plus
  /// the particle id as one extra last column when with_id is set.
  void pack(const std::vector<int>& sel, bool with_id, std::vector<double>& out);

  int ncols() const { return static_cast<int>(fields.size()); }
  /// Index of the field with this exact name, -1 if absent.
  int find(const std::string& name) const;

  std::vector<DumpField> fields;

 private:
  void property_column(const AtomProperty& prop, const std::vector<int>& sel, int stride, double* out) const;
  Engine& engine_;
  std::string what_;
  std::vector<double> scratch_;
};

namespace dumpio {

/// Gather row-major rows of `ncols` doubles to rank 0 of `comm`; on rank 0,
/// `all` receives every rank's rows in rank order. Returns the total row count
/// on rank 0 (0 elsewhere).
std::int64_t gather_rows(MPI_Comm comm, const std::vector<double>& local, int ncols,
                         std::vector<double>& all);

/// Replace the first '*' in `pattern` by the step, zero-padded to `pad` digits.
std::string expand(const std::string& pattern, std::int64_t step, int pad);

/// InputError (on every rank) naming `file` when its directory does not exist
/// or is not a directory; rank 0 checks and broadcasts.
void check_directory(MPI_Comm comm, const std::string& file, const std::string& what);

/// `dump_modify ID pvd NAME|no|off|none` of the VTK XML dumps at args[k]:
/// sets `path` to the collection file (empty for none) and returns 2, or
/// returns 0 when args[k] is not `pvd` with a value. `legacy`: the dump
/// writes legacy .vtk frames, which a collection cannot list (an error).
int parse_pvd(MPI_Comm comm, const Args& args, std::size_t k, const std::string& where, bool legacy,
              std::string& path);

/// Collective: returns the message of the lowest rank whose `local_error` is
/// not empty, or an empty string on every rank when none failed.
std::string first_error(MPI_Comm comm, const std::string& local_error);

/// "cannot write 'file': reason" with the system's reason for errno.
std::string open_error(const std::string& file);

/// Append the LAMMPS text-dump frame header from "ITEM: TIMESTEP" to the
/// box bounds: `count_item` is "ATOMS" (dump custom) or "ENTRIES" (dump local).
void append_frame_header(std::string& out, const Engine& e, const char* count_item, std::int64_t nrows);

/// The printf formats of the columns of a text dump (dump custom, dump
/// local): `dump_modify format` and `precision`, then one format per column.
class ColumnFormats {
 public:
  /// Set the number of columns (clears the per-column formats when it changes).
  void resize(int ncols);
  /// `format ...` or `precision P` at args[k]: the number of words used (0:
  /// not one of them). `where` names the command in messages.
  int modify_param(const Args& args, std::size_t k, const std::string& where);
  /// Resolve one format per column; integer[c]: column c holds integers.
  void build(const std::vector<bool>& integer);
  bool built(int ncols) const { return static_cast<int>(formats_.size()) == ncols; }
  /// Append one row, its values separated by blanks, and a newline.
  void append_row(std::string& out, const double* row) const;

 private:
  struct Format {
    std::string spec;  // printf specification with its text, "ll" added for integers
    bool integer = false;
  };
  static Format parse(const std::string& text);
  int ncols_ = 0;
  int precision_ = 0;                    // significant digits of the default float format (0 = %g)
  std::vector<std::string> col_format_;  // per-column user format ("" = none)
  std::string int_format_, float_format_;
  std::vector<std::string> line_format_;
  std::vector<Format> formats_;  // resolved, one per column
};

}  // namespace dumpio

class DumpCustom : public Dump {
 public:
  DumpCustom(Engine& engine, const Args& args);
  ~DumpCustom() override;

  void init() override;
  void write() override;
  int modify_param(const Args& args, std::size_t k) override;
  void finish() override;

 protected:
  /// One frame: the header, then the rows in the dump's sort order. Styles
  /// with another text layout (dump xyz) write their own header here.
  virtual void write_frame(std::FILE* fp, const std::vector<double>& rows, std::int64_t nrows, int stride);
  /// Append the rows in the dump's sort order (`stride` values per row, the
  /// id last when sorting by id), writing `out` to fp as it grows.
  void append_rows(std::FILE* fp, std::string& out, const std::vector<double>& rows, std::int64_t nrows,
                   int stride);

 private:
  void build_formats();

  DumpFields fields_;
  bool multifile_ = false;  // '*' in the file name: one file per frame
  bool append_ = false;
  int pad_ = 0;
  int sort_ = 0;  // 0 off, kSortId by id, +-(column) ascending/descending
  static constexpr int kSortId = 1 << 30;
  bool time_flag_ = false, units_flag_ = false, units_written_ = false;
  std::string label_ = "ATOMS";
  dumpio::ColumnFormats formats_;
  std::FILE* fp_ = nullptr;  // single-file mode, open on rank 0
  std::string columns_;      // header column names
};

}  // namespace granary
