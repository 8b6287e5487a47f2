// Base class of dump styles (`dump ID group style N file args...`).
//
// Dumps register with GRANARY_DUMP_STYLE. Output calls write() on every rank
// together at steps that are multiples of `every` (and at the start of a run),
// so a dump may gather data to rank 0 or write one piece per rank.
#pragma once

#include <cstdint>
#include <string>

#include "core/utils.h"

namespace granary {

class Engine;

class Dump {
 public:
  /// args = "ID group-ID style N file style-args..."
  Dump(Engine& engine, const Args& args);
  virtual ~Dump() = default;

  /// Before every run (check fields, open files).
  virtual void init() {}
  /// Write the current step (collective).
  virtual void write() = 0;
  /// dump_modify keywords this style understands; return the number of words
  /// consumed at args[k] (0 = unknown). The base handles every/first.
  virtual int modify_param(const Args& args, std::size_t k) { return 0; }
  /// Called when the dump is removed (undump) or the engine ends: finish files.
  virtual void finish() {}
  /// write_dump writes one file: a style that keeps a collection of its frames
  /// (a ParaView .pvd) drops it here (`modify pvd NAME` can ask for one again).
  virtual void single_file() {}

  void modify(const Args& args);

  std::string id, style, filename;
  int igroup = 0, groupbit = 1;
  int every = 1;
  bool first = false;  // write at the first step of every run even if not a multiple
  std::int64_t last_step = -1;

 protected:
  /// `dump_modify ID region R|none` for styles that write particles: returns
  /// the words used (0 when args[k] is not `region`).
  int parse_region(const Args& args, std::size_t k, const std::string& where);
  std::string region_;  // only particles inside this region are written ("" = all)

  Engine& engine_;
  Args args_;
};

}  // namespace granary
