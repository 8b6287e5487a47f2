#include "output/output.h"

#include <algorithm>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "domain/region.h"
#include "output/dump.h"
#include "output/restart.h"

namespace granary {

Dump::Dump(Engine& engine, const Args& args) : engine_(engine), args_(args) {
  if (args.size() < 5) throw InputError("usage: dump ID group-ID style N file args...");
  id = args[0];
  igroup = engine.groups->find_or_error(args[1], "dump " + args[0]);
  groupbit = engine.groups->bitmask(igroup);
  style = args[2];
  const long long n = parse_int(args[3], "dump interval N");
  if (n <= 0) throw InputError("dump interval must be a positive number of steps");
  every = static_cast<int>(n);
  filename = args[4];
}

void Dump::modify(const Args& args) {
  for (std::size_t k = 1; k < args.size();) {
    if (args[k] == "every" && k + 1 < args.size()) {
      const long long n = parse_int(args[k + 1], "dump_modify every");
      if (n <= 0) throw InputError("dump_modify every needs a positive number of steps");
      every = static_cast<int>(n);
      k += 2;
      continue;
    }
    if (args[k] == "first" && k + 1 < args.size()) {
      first = parse_bool(args[k + 1], "dump_modify first");
      k += 2;
      continue;
    }
    const int used = modify_param(args, k);
    if (used <= 0) {
      throw InputError("dump_modify: keyword '" + args[k] + "' is not known to dump style " + style);
    }
    k += used;
  }
}

int Dump::parse_region(const Args& args, std::size_t k, const std::string& where) {
  if (args[k] != "region" || k + 1 >= args.size()) return 0;
  if (args[k + 1] == "none")
    region_.clear();
  else
    region_ = engine_.domain->region_or_error(args[k + 1], where)->id;
  return 2;
}

Output::Output(Engine& engine) : engine_(engine) {}

Output::~Output() {
  for (auto& d : dumps)
    d->finish();
}

void Output::add_dump(const Args& args) {
  if (args.size() < 3) throw InputError("usage: dump ID group-ID style N file args...");
  if (find_dump(args[0])) throw InputError("dump ID '" + args[0] + "' is already used; undump it first");
  const auto& registry = DumpRegistry::instance();
  const DumpFactory* factory = registry.find(args[2]);
  if (!factory) {
    const std::string hint = did_you_mean(args[2], registry.names());
    throw InputError("unknown dump style '" + args[2] + "'" + (hint.empty() ? "" : "; " + hint));
  }
  dumps.push_back((*factory)(engine_, args));
  next = -1;
}

void Output::delete_dump(const std::string& id) {
  for (auto it = dumps.begin(); it != dumps.end(); ++it) {
    if ((*it)->id == id) {
      (*it)->finish();
      dumps.erase(it);
      return;
    }
  }
  throw InputError("undump: unknown dump ID '" + id + "'");
}

Dump* Output::find_dump(const std::string& id) const {
  for (const auto& d : dumps)
    if (d->id == id) return d.get();
  return nullptr;
}

void Output::modify_dump(const Args& args) {
  if (args.size() < 2) throw InputError("usage: dump_modify ID keyword value ...");
  Dump* d = find_dump(args[0]);
  if (!d) throw InputError("dump_modify: unknown dump ID '" + args[0] + "'");
  d->modify(args);
}

void Output::restart_command(const Args& args) {
  require_args(args, 1, 3, "restart 0 | restart N FILE [FILE2]");
  const long long n = parse_int(args[0], "restart interval");
  if (n < 0) throw InputError("restart interval must be >= 0");
  restart_every = static_cast<int>(n);
  if (n == 0) return;
  if (args.size() < 2) throw InputError("restart N needs a file name: restart N FILE [FILE2]");
  restart_file1 = args[1];
  restart_file2 = args.size() == 3 ? args[2] : "";
  restart_toggle = false;
}

void Output::schedule(std::int64_t step) {
  std::int64_t n = -1;
  auto consider = [&](std::int64_t every) {
    if (every <= 0) return;
    const std::int64_t due = (step / every + 1) * every;
    if (n < 0 || due < n) n = due;
  };
  for (const auto& d : dumps)
    consider(d->every);
  consider(restart_every);
  next = n;
}

void Output::setup() {
  const std::int64_t step = engine_.update->ntimestep;
  for (auto& d : dumps) {
    d->init();
    if ((step % d->every == 0 || d->first) && d->last_step != step) {
      d->write();
      d->last_step = step;
    }
  }
  schedule(step);
}

void Output::write(std::int64_t step) {
  if (next < 0 || step < next) return;
  for (auto& d : dumps) {
    if (step % d->every == 0 && d->last_step != step) {
      d->write();
      d->last_step = step;
    }
  }
  if (restart_every > 0 && step % restart_every == 0) write_restart_now(step);
  schedule(step);
}

std::string Output::write_restart_now(std::int64_t step) {
  if (restart_every <= 0) return "";
  if (restart_step == step) return restart_last;
  std::string file = restart_file1;
  if (!restart_file2.empty()) {
    file = restart_toggle ? restart_file2 : restart_file1;
    restart_toggle = !restart_toggle;
  }
  restart_last = expand_step(file, step);
  write_restart(engine_, restart_last);
  restart_step = step;
  return restart_last;
}

void cmd_dump(Engine& e, const Args& a) {
  e.output->add_dump(a);
}
void cmd_undump(Engine& e, const Args& a) {
  require_args(a, 1, 1, "undump ID");
  e.output->delete_dump(a[0]);
}
void cmd_dump_modify(Engine& e, const Args& a) {
  e.output->modify_dump(a);
}
void cmd_restart(Engine& e, const Args& a) {
  e.output->restart_command(a);
}
GRANARY_COMMAND("dump", cmd_dump);
GRANARY_COMMAND("undump", cmd_undump);
GRANARY_COMMAND("dump_modify", cmd_dump_modify);
GRANARY_COMMAND("restart", cmd_restart);

}  // namespace granary
