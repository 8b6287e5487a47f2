// `write_dump group-ID style file fields... [modify keyword value ...]`:
// write the current state once with any dump style (custom, custom/vtk,
// bodies/vtk, mesh/vtk, mesh/stl).
#include <memory>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "output/dump.h"

namespace granary {

namespace {

void cmd_write_dump(Engine& e, const Args& a) {
  if (a.size() < 3) {
    throw InputError("usage: write_dump group-ID style file fields... [modify keyword value ...]");
  }
  if (!e.domain->box_exist)
    throw InputError("write_dump: the box does not exist yet (create_box or read_restart first)");
  const auto& registry = DumpRegistry::instance();
  const DumpFactory* factory = registry.find(a[1]);
  if (!factory) {
    const std::string hint = did_you_mean(a[1], registry.names());
    throw InputError("write_dump: unknown dump style '" + a[1] + "'" + (hint.empty() ? "" : "; " + hint));
  }
  // the same arguments as `dump write_dump GROUP STYLE 1 FILE fields...`
  Args dump_args{"write_dump", a[0], a[1], "1", a[2]};
  std::size_t k = 3;
  for (; k < a.size() && a[k] != "modify"; ++k)
    dump_args.push_back(a[k]);
  std::unique_ptr<Dump> dump = (*factory)(e, dump_args);

  dump->single_file();
  Args modify_args{"write_dump"};
  for (++k; k < a.size(); ++k)
    modify_args.push_back(a[k]);
  if (modify_args.size() > 1) dump->modify(modify_args);

  dump->init();
  try {
    dump->write();
  } catch (const RunError& err) {
    dump->finish();
    throw InputError(err.what());
  }
  dump->finish();
}

}  // namespace

GRANARY_COMMAND("write_dump", cmd_write_dump);

}  // namespace granary
