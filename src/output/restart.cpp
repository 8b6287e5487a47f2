// Restart files: format and the write_restart / read_restart commands.
//
// Layout (little or big endian as written; the byte-order mark tells):
//   char     magic[16]      "GRANARY-RESTART"
//   uint32   version        kVersion
//   uint32   byte_order     0x01020304
//   uint32   nsections
//   uint32   table_crc      CRC-32 of the section table
//   table    nsections x { char name[32]; uint64 offset; uint64 size; uint32 crc; uint32 zero }
//   data     the sections, each checksummed with CRC-32
// Sections: "global" (text, one "key value..." per line), "particles",
// "contact_history", "fixes", "materials". See doc/restart_format.md.
#include "output/restart.h"

#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "comm/collectives.h"
#include "comm/comm.h"
#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "fix/fix.h"
#include "particles/clumps.h"
#include "fix/fix_property_global.h"
#include "core/modify.h"
#include "neighbor/contact_history.h"
#include "neighbor/neighbor.h"
#include "core/force.h"
#include "pair/pair.h"
#include "particles/particles.h"

namespace granary {

namespace {

constexpr char kMagic[16] = "GRANARY-RESTART";
constexpr std::uint32_t kVersion = 1;
constexpr std::uint32_t kByteOrder = 0x01020304;
constexpr std::size_t kNameBytes = 32;
constexpr int kCoreFields = 23;  // doubles per particle before the extra fields

// CRC-32 of data[0..n) continued from `crc` (0 for a new checksum).
std::uint32_t crc32(const char* data, std::size_t n, std::uint32_t crc = 0) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k)
        c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = crc ^ 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i)
    c = table[(c ^ static_cast<unsigned char>(data[i])) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

void put_string(std::string& out, const std::string& s) {
  put<std::uint64_t>(out, s.size());
  out += s;
}

// Bounds-checked reading of one section.
class Reader {
 public:
  /// `beyond`: bytes of the section that follow `data` in the file (a reader
  /// of a section's first part counts them in check_count)
  Reader(std::string_view data, const std::string& file, const std::string& section, std::uint64_t beyond = 0)
      : data_(data), file_(file), section_(section), beyond_(beyond) {}
  template <class T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string get_string() {
    const auto n = get<std::uint64_t>();
    need(n);
    std::string s(data_.substr(pos_, n));
    pos_ += n;
    return s;
  }
  void get_doubles(double* out, std::size_t n) {
    if (n > remaining() / sizeof(double)) need(remaining() + 1);
    if (n == 0) return;  // (out may be the null data() of an empty vector)
    std::memcpy(out, data_.data() + pos_, n * sizeof(double));
    pos_ += n * sizeof(double);
  }
  bool done() const { return pos_ == data_.size(); }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }
  /// A count read from the file that announces `count` items of at least
  /// `bytes_each` bytes still to come: refused before anything is allocated
  /// for them when the section cannot hold that many.
  void check_count(std::uint64_t count, std::size_t bytes_each, const char* what) const {
    const std::uint64_t left = remaining() + beyond_;
    if (bytes_each > 0 && count > left / bytes_each) {
      throw InputError(
          "restart file '" + file_ + "': section '" + section_ + "' announces " + std::to_string(count) +
          " " + what + ", more than its " + std::to_string(left) +
          " remaining bytes hold; the file is corrupted or was written by an incompatible program");
    }
  }

 private:
  void need(std::size_t n) const {
    if (n > remaining()) {
      throw InputError("restart file '" + file_ + "': section '" + section_ +
                       "' ends early; the file is corrupted or was written by an incompatible program");
    }
  }
  std::string_view data_;
  std::string file_, section_;
  std::uint64_t beyond_ = 0;
  std::size_t pos_ = 0;
};

// Raise the same InputError on every rank when rank 0 found a problem.
void agree(Engine& e, const std::string& problem_on_rank0) {
  std::string msg = problem_on_rank0;
  bcast_string(e.world, msg);
  if (!msg.empty()) throw InputError(msg);
}

std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// --------------------------------------------------------------------- write

// Rank 0 only: no collective calls in here.
std::string global_section(Engine& e, long long natoms) {
  const Domain& d = *e.domain;
  const Update& u = *e.update;
  std::ostringstream s;
  s << "program Granary\n";
  s << "format_version " << kVersion << "\n";
  s << "written_on_ranks " << e.nprocs << "\n";
  s << "units " << d.units << "\n";
  s << "dimension " << d.dimension << "\n";
  const Particles& p = *e.particles;
  s << "atom_style " << (p.sph ? "sph" : "granular") << "\n";
  if (p.sph) {
    s << "type_mass";
    for (int t = 1; t <= p.ntypes; ++t)
      s << " " << fmt(t < static_cast<int>(p.type_mass.size()) ? p.type_mass[t] : 0.0);
    s << "\n";
    if (!p.sph_kernel.empty()) s << "sph_kernel " << p.sph_kernel << "\n";
  }
  s << "step " << u.ntimestep << "\n";
  s << "atime " << fmt(u.atime) << "\n";
  s << "atimestep " << u.atimestep << "\n";
  s << "dt " << fmt(u.dt) << "\n";
  // whether the stored forces belong to the stored state (see Update::forces_current)
  s << "forces_current " << (u.forces_current ? 1 : 0) << "\n";
  s << "boundary";
  for (int k = 0; k < 3; ++k)
    s << " " << d.boundary[k][0] << d.boundary[k][1];
  s << "\n";
  s << "boxlo " << fmt(d.boxlo[0]) << " " << fmt(d.boxlo[1]) << " " << fmt(d.boxlo[2]) << "\n";
  s << "boxhi " << fmt(d.boxhi[0]) << " " << fmt(d.boxhi[1]) << " " << fmt(d.boxhi[2]) << "\n";
  s << "minlo " << fmt(d.minlo[0]) << " " << fmt(d.minlo[1]) << " " << fmt(d.minlo[2]) << "\n";
  s << "minhi " << fmt(d.minhi[0]) << " " << fmt(d.minhi[1]) << " " << fmt(d.minhi[2]) << "\n";
  s << "ntypes " << e.particles->ntypes << "\n";
  s << "natoms " << natoms << "\n";
  s << "newton " << (e.force->newton_pair ? "on" : "off") << "\n";
  const Neighbor& n = *e.neighbor;
  s << "neighbor " << fmt(n.skin) << " " << n.every << " " << n.delay << " " << (n.check ? 1 : 0) << " "
    << n.sort_every << " " << fmt(n.sort_binsize) << "\n";
  for (int g = 0; g < Groups::kMaxGroups; ++g)
    if (!e.groups->names[g].empty()) s << "group " << g << " " << e.groups->names[g] << "\n";
  if (e.force->pair) s << "pair_style " << e.force->pair->style << " " << join(e.force->pair_words) << "\n";
  return s.str();
}

std::string particles_section(Engine& e) {
  const Particles& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i) {
    mine.push_back(static_cast<double>(p.id[i]));
    mine.push_back(p.type[i]);
    mine.push_back(p.mask[i]);
    for (const auto* a : {&p.x, &p.v, &p.omega, &p.f, &p.torque})
      for (int d = 0; d < 3; ++d)
        mine.push_back((*a)[i][d]);
    mine.push_back(p.radius[i]);
    mine.push_back(p.density[i]);
    mine.push_back(p.rmass[i]);
    mine.push_back(static_cast<double>(p.body[i]));
    mine.push_back(p.image[i]);
    for (const auto& f : p.extras) {
      if (!f.exchange || !f.restart) continue;
      const double* src = &f.data[static_cast<std::size_t>(i) * f.ncomp];
      mine.insert(mine.end(), src, src + f.ncomp);
    }
  }
  std::vector<double> all = gather_to_root(e.world, mine);
  std::string out;
  if (e.rank != 0) return out;
  int per = kCoreFields;
  std::vector<std::string> names;
  std::vector<int> ncomp;
  for (const auto& f : p.extras) {
    if (!f.exchange || !f.restart) continue;
    names.push_back(f.name);
    ncomp.push_back(f.ncomp);
    per += f.ncomp;
  }
  put<std::uint64_t>(out, all.size() / per);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(names.size()));
  for (std::size_t k = 0; k < names.size(); ++k) {
    put_string(out, names[k]);
    put<std::uint32_t>(out, static_cast<std::uint32_t>(ncomp[k]));
  }
  out.append(reinterpret_cast<const char*>(all.data()), all.size() * sizeof(double));
  return out;
}

std::string history_section(Engine& e) {
  std::vector<double> mine;
  ContactHistory* h = e.force->contact_history();
  if (h) {  // (the history read from a restart file while no pair style has taken it)
    if (e.update->running) h->save(*e.neighbor, *e.particles);
    h->pack_all(mine);
  }
  // each rank: count, nvalues, entries; merge on rank 0 (newton off keeps
  // cross-rank contacts on both ranks: identical entries, kept once)
  std::vector<double> all = gather_to_root(e.world, mine);
  std::string out;
  if (e.rank != 0) return out;
  std::map<std::pair<long long, long long>, std::vector<double>> merged;
  int nvalues = 0;
  std::size_t m = 0;
  while (m + 2 <= all.size()) {
    const auto count = static_cast<std::size_t>(all[m]);
    nvalues = static_cast<int>(all[m + 1]);
    m += 2;
    for (std::size_t c = 0; c < count; ++c) {
      const auto a = static_cast<long long>(all[m]), b = static_cast<long long>(all[m + 1]);
      merged[{a, b}] = std::vector<double>(all.begin() + m + 2, all.begin() + m + 2 + nvalues);
      m += 2 + nvalues;
    }
  }
  put<std::uint64_t>(out, merged.size());
  put<std::uint32_t>(out, static_cast<std::uint32_t>(nvalues));
  for (const auto& kv : merged) {
    put<std::int64_t>(out, kv.first.first);
    put<std::int64_t>(out, kv.first.second);
    out.append(reinterpret_cast<const char*>(kv.second.data()), kv.second.size() * sizeof(double));
  }
  return out;
}

std::string fixes_section(Engine& e) {
  std::string out;
  std::vector<std::pair<std::string, const Fix*>> with_state;
  for (const auto& f : e.modify->fixes)
    if (f->restart_global) with_state.emplace_back(f->id, f.get());
  // states of fixes read from a restart but not defined again are kept
  put<std::uint32_t>(out, static_cast<std::uint32_t>(with_state.size() + e.modify->restart_states.size()));
  for (const auto& kv : with_state) {
    std::string data;
    kv.second->pack_restart(data);
    put_string(out, kv.first);
    put_string(out, kv.second->style);
    put_string(out, data);
  }
  for (const auto& kv : e.modify->restart_states) {
    put_string(out, kv.first);
    put_string(out, kv.second.style);
    put_string(out, kv.second.data);
  }
  return out;
}

std::string materials_section(Engine& e) {
  std::string out;
  std::vector<const FixPropertyGlobal*> props;
  for (const auto& f : e.modify->fixes)
    if (auto* p = dynamic_cast<const FixPropertyGlobal*>(f.get())) props.push_back(p);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(props.size()));
  for (const auto* p : props) {
    put_string(out, p->name);
    put<std::uint64_t>(out, p->values.size());
    out.append(reinterpret_cast<const char*>(p->values.data()), p->values.size() * sizeof(double));
  }
  return out;
}

// ---------------------------------------------------------------------- read

// Rank 0's view of a restart file: the small sections in memory, the large
// ones (particles, contact history) read from the file in pieces when needed.
struct FileSections {
  std::string file;
  std::ifstream in;
  std::vector<std::string> names;                     // in the file's order
  std::map<std::string, std::string> small;           // held in memory
  std::map<std::string, std::uint64_t> offset, size;  // of every section in the file
  bool has(const std::string& name) const { return size.count(name) > 0; }
  bool held(const std::string& name) const { return small.count(name) > 0; }
  /// Up to n bytes of the file from `pos` (fewer where it ends); returns how many.
  std::size_t read_file(std::uint64_t pos, std::size_t n, char* out) {
    in.clear();
    in.seekg(static_cast<std::streamoff>(pos));
    in.read(out, static_cast<std::streamsize>(n));
    return static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0));
  }
  /// Bytes [pos, pos + n) of a section.
  void read(const std::string& name, std::uint64_t pos, std::size_t n, char* out) {
    if (held(name)) {
      std::memcpy(out, small.at(name).data() + pos, n);
      return;
    }
    if (read_file(offset.at(name) + pos, n, out) != n) {
      throw InputError("restart file '" + file +
                       "' changed or became unreadable while being read (section '" + name +
                       "'); read it again");
    }
  }
  /// The first min(n, size) bytes of a section.
  std::string prefix(const std::string& name, std::size_t n) {
    std::string out(static_cast<std::size_t>(std::min<std::uint64_t>(n, size.at(name))), '\0');
    read(name, 0, out.size(), out.data());
    return out;
  }
};

constexpr std::size_t kChunkBytes = std::size_t{8} << 20;

bool large_section(const std::string& name) {
  return name == "particles" || name == "contact_history";
}

// Rank 0: open the file and check its header, section table and every
// section's checksum (reading it in pieces); returns an error message or "".
std::string load(const std::string& file, FileSections& out) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    return "'" + file + "' is a directory, not a restart file; give the restart file's name";
  out.file = file;
  std::ifstream& in = out.in;
  in.open(file, std::ios::binary);
  if (!in) return "cannot open restart file '" + file + "'; check the name and that it exists";
  in.seekg(0, std::ios::end);
  const auto file_size = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  auto read_at = [&](std::uint64_t pos, std::size_t n) {
    std::string b(n, '\0');
    b.resize(out.read_file(pos, n, b.data()));
    return b;
  };
  const std::size_t head = 16 + 4 * 4;
  const std::string header = read_at(0, static_cast<std::size_t>(std::min<std::uint64_t>(file_size, head)));
  if (header.size() < 16 || std::memcmp(header.data(), kMagic, 16) != 0) {
    return "'" + file + "' is not a Granary restart file (its header does not start with " +
           std::string(kMagic) + ")";
  }
  if (header.size() < head) {
    return "restart file '" + file + "' is truncated: " + std::to_string(file_size) +
           " bytes, fewer than the " + std::to_string(head) + " of its header";
  }
  std::uint32_t version, order, nsections, table_crc;
  std::memcpy(&version, header.data() + 16, 4);
  std::memcpy(&order, header.data() + 20, 4);
  std::memcpy(&nsections, header.data() + 24, 4);
  std::memcpy(&table_crc, header.data() + 28, 4);
  if (order == __builtin_bswap32(kByteOrder)) {
    return "restart file '" + file +
           "' was written on a machine with the other byte order; "
           "convert it there with write_dump or rewrite it on a machine like this one";
  }
  if (order != kByteOrder) {
    char mark[16];
    std::snprintf(mark, sizeof mark, "0x%08x", order);
    return "restart file '" + file + "' is corrupted: its byte-order mark is " + mark +
           ", neither this machine's byte order nor the other one";
  }
  if (version != kVersion) {
    return "restart file '" + file + "' has format version " + std::to_string(version) +
           "; this Granary reads version " + std::to_string(kVersion);
  }
  const std::size_t entry = kNameBytes + 8 + 8 + 4 + 4;
  if (nsections > 64 || file_size < head + nsections * entry) {
    return "restart file '" + file + "' is truncated (its section table is incomplete)";
  }
  const std::string table = read_at(head, nsections * entry);
  if (table.size() != nsections * entry || crc32(table.data(), table.size()) != table_crc) {
    return "restart file '" + file + "' is corrupted (checksum of its section table does not match)";
  }
  std::string piece;
  for (std::uint32_t k = 0; k < nsections; ++k) {
    const char* t = table.data() + k * entry;
    std::string name(t, strnlen(t, kNameBytes));
    std::uint64_t offset, size;
    std::uint32_t crc;
    std::memcpy(&offset, t + kNameBytes, 8);
    std::memcpy(&size, t + kNameBytes + 8, 8);
    std::memcpy(&crc, t + kNameBytes + 16, 4);
    if (offset + size > file_size || offset + size < offset) {
      return "restart file '" + file + "' is truncated: section '" + name + "' needs bytes up to " +
             std::to_string(offset + size) + " but the file has " + std::to_string(file_size);
    }
    std::uint32_t c = 0;
    std::string kept;
    for (std::uint64_t pos = 0; pos < size; pos += kChunkBytes) {
      piece =
          read_at(offset + pos, static_cast<std::size_t>(std::min<std::uint64_t>(kChunkBytes, size - pos)));
      c = crc32(piece.data(), piece.size(), c);
      if (!large_section(name)) kept += piece;
    }
    if (c != crc) {
      return "restart file '" + file + "' is corrupted: the checksum of section '" + name +
             "' does not match";
    }
    if (!out.has(name)) out.names.push_back(name);
    out.offset[name] = offset;
    out.size[name] = size;
    if (!large_section(name)) out.small[name] = std::move(kept);
  }
  for (const char* needed : {"global", "particles"}) {
    if (!out.has(needed)) return "restart file '" + file + "' has no '" + needed + "' section";
  }
  return "";
}

std::map<std::string, std::vector<std::string>> parse_global(const std::string& text) {
  std::map<std::string, std::vector<std::string>> kv;
  std::istringstream in(text);
  std::string line;
  int group_line = 0;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string key, w;
    ls >> key;
    std::vector<std::string> words;
    while (ls >> w)
      words.push_back(w);
    if (key == "group") key += "#" + std::to_string(group_line++);
    kv[key] = words;
  }
  return kv;
}

}  // namespace

std::string expand_step(const std::string& file, std::int64_t step) {
  const auto star = file.find('*');
  if (star == std::string::npos) return file;
  return file.substr(0, star) + std::to_string(step) + file.substr(star + 1);
}

void write_restart(Engine& e, const std::string& file) {
  if (!e.domain->box_exist)
    throw InputError("write_restart needs a box and particles: create_box or read_restart first");
  // clump records: rank 0 writes every body's state, which only the ranks
  // owning its sub-spheres keep current during a run
  if (e.clumps) e.clumps->sync_bodies();
  for (const auto& f : e.modify->fixes)
    if (f->restart_global) f->prepare_restart();
  std::vector<std::pair<std::string, std::string>> sections;
  const long long natoms = e.update->count_global();
  sections.emplace_back("global", e.rank == 0 ? global_section(e, natoms) : "");
  sections.emplace_back("particles", particles_section(e));
  sections.emplace_back("contact_history", history_section(e));
  sections.emplace_back("fixes", e.rank == 0 ? fixes_section(e) : "");
  sections.emplace_back("materials", e.rank == 0 ? materials_section(e) : "");
  std::string problem;
  if (e.rank == 0) {
    const std::size_t head = 16 + 16, entry = kNameBytes + 8 + 8 + 4 + 4;
    std::string table;
    std::uint64_t offset = head + sections.size() * entry;
    for (const auto& s : sections) {
      char name[kNameBytes] = {0};
      std::strncpy(name, s.first.c_str(), kNameBytes - 1);
      table.append(name, kNameBytes);
      put<std::uint64_t>(table, offset);
      put<std::uint64_t>(table, s.second.size());
      put<std::uint32_t>(table, crc32(s.second.data(), s.second.size()));
      put<std::uint32_t>(table, 0);
      offset += s.second.size();
    }
    std::string header(kMagic, 16);
    put<std::uint32_t>(header, kVersion);
    put<std::uint32_t>(header, kByteOrder);
    put<std::uint32_t>(header, static_cast<std::uint32_t>(sections.size()));
    put<std::uint32_t>(header, crc32(table.data(), table.size()));
    problem = replace_file(file, [&](std::FILE* f) {
      std::fwrite(header.data(), 1, header.size(), f);
      std::fwrite(table.data(), 1, table.size(), f);
      for (const auto& s : sections)
        std::fwrite(s.second.data(), 1, s.second.size(), f);
    });
    if (!problem.empty()) problem = "restart file: " + problem;
  }
  agree(e, problem);
  e.logger->print("Wrote restart file " + file + " at step " + std::to_string(e.update->ntimestep) + "\n");
}

void read_restart(Engine& e, const std::string& file) {
  if (e.domain->box_exist) {
    throw InputError("read_restart must come before the box is created; use clear first to start over");
  }
  FileSections fs;
  std::string problem;
  if (e.rank == 0) problem = load(file, fs);
  agree(e, problem);
  // Every rank gets every section but the particle records, which stay on
  // rank 0 and go out in chunks once the subdomains are known (each rank
  // keeps its own): no rank ever holds all particles twice. The contact
  // history is parsed on rank 0 and its values sent out in chunks.
  std::map<std::string, std::string> sec;
  std::uint32_t n = static_cast<std::uint32_t>(fs.names.size());
  MPI_Bcast(&n, 1, MPI_UINT32_T, 0, e.world);
  std::vector<std::string> names;
  names = fs.names;
  names.resize(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    bcast_string(e.world, names[k]);
    const bool bulk =
        names[k] == "particles" || names[k] == "contact_history" || names[k] == "fixes";  // (below)
    if (bulk) continue;
    if (e.rank == 0) sec[names[k]] = std::move(fs.small[names[k]]);
    bcast_string(e.world, sec[names[k]]);
  }

  // Parse everything before changing any state, so a bad file changes nothing.
  auto g = parse_global(sec["global"]);
  auto bad = [&](const std::string& what) {
    return InputError("restart file '" + file + "': " + what +
                      "; the file is corrupted or was written by an incompatible program");
  };
  // a global value that is not a number: the same error as any other bad value
  auto pint = [&](const std::string& word, const std::string& what) {
    try {
      return parse_int(word, what);
    } catch (const InputError& err) {
      throw bad(err.what());
    }
  };
  auto pdouble = [&](const std::string& word, const std::string& what) {
    try {
      return parse_double(word, what);
    } catch (const InputError& err) {
      throw bad(err.what());
    }
  };
  auto need = [&](const std::string& key, std::size_t count) -> const std::vector<std::string>& {
    auto it = g.find(key);
    if (it == g.end() || it->second.size() < count) {
      throw bad("the global section lacks '" + key + "'");
    }
    return it->second;
  };
  auto vec = [&](const std::string& key) {
    const auto& w = need(key, 3);
    return Vec3(pdouble(w[0], key), pdouble(w[1], key), pdouble(w[2], key));
  };
  const std::string units = need("units", 1)[0];
  const bool sph_file = g.count("atom_style") && !g["atom_style"].empty() && g["atom_style"][0] == "sph";
  const auto step = pint(need("step", 1)[0], "step");
  const double atime = pdouble(need("atime", 1)[0], "atime");
  const auto atimestep = pint(need("atimestep", 1)[0], "atimestep");
  const double dt = pdouble(need("dt", 1)[0], "dt");
  // (files without the key predate it and were always written after a run)
  const bool forces_current =
      !g.count("forces_current") || g["forces_current"].empty() || g["forces_current"][0] == "1";
  const auto& bnd = need("boundary", 3);
  const Vec3 boxlo = vec("boxlo"), boxhi = vec("boxhi"), minlo = vec("minlo"), minhi = vec("minhi");
  const long long ntypes_read = pint(need("ntypes", 1)[0], "ntypes");
  const auto& nb = need("neighbor", 6);
  // the global values, checked before anything is applied
  if (ntypes_read < 1 || ntypes_read > Particles::kMaxTypes)
    throw bad("the number of atom types " + std::to_string(ntypes_read) + " is outside 1.." +
              std::to_string(Particles::kMaxTypes));
  const int ntypes = static_cast<int>(ntypes_read);
  for (int k = 0; k < 3; ++k) {
    if (!(std::isfinite(boxlo[k]) && std::isfinite(boxhi[k]) && boxlo[k] < boxhi[k]))
      throw bad("the box bounds are not finite numbers with lo < hi");
    if (!(std::isfinite(minlo[k]) && std::isfinite(minhi[k]) && minlo[k] <= minhi[k]))
      throw bad("the initial box bounds are not finite numbers with lo <= hi");
    if (bnd[k].empty() || bnd[k].size() > 2 || bnd[k].find_first_not_of("pfsm") != std::string::npos)
      throw bad("boundary '" + bnd[k] + "' is not one of p, f, s, m (or two of them)");
  }
  if (!(std::isfinite(dt) && dt > 0.0)) throw bad("the timestep is not a positive number");
  if (step < 0 || atimestep < 0 || atimestep > step || !std::isfinite(atime))
    throw bad("the step or time is not valid");
  if (units != "si" && units != "cgs") throw bad("unknown units '" + units + "'");
  const double skin_read = pdouble(nb[0], "skin");
  long long neigh_int[4] = {pint(nb[1], "every"), pint(nb[2], "delay"), 0, pint(nb[4], "sort")};
  const double sort_binsize = pdouble(nb[5], "sort binsize");
  if (!(std::isfinite(skin_read) && skin_read >= 0.0) ||
      !(std::isfinite(sort_binsize) && sort_binsize >= 0.0))
    throw bad("the neighbour skin or sort bin size is not a number >= 0");
  for (long long v : neigh_int)
    if (v < 0 || v > 1000000000) throw bad("a neighbour setting is outside 0..1e9");
  if (neigh_int[0] < 1)
    throw bad("the neighbour list interval 'every' is " + std::to_string(neigh_int[0]) + ", not >= 1");
  std::vector<std::pair<int, std::string>> group_names;
  for (const auto& kv : g) {
    if (kv.first.rfind("group#", 0) != 0 || kv.second.size() < 2) continue;
    const long long index = pint(kv.second[0], "group index");
    if (index < 0 || index >= Groups::kMaxGroups)
      throw bad("group index " + std::to_string(index) + " is outside 0.." +
                std::to_string(Groups::kMaxGroups - 1));
    group_names.emplace_back(static_cast<int>(index), kv.second[1]);
  }

  // The particles section: its header (count, extra fields) on every rank;
  // the records are checked on rank 0, in place.
  std::string phead;
  std::uint64_t records_at = 0;  // rank 0: where the records start in the section
  problem.clear();
  if (e.rank == 0) {
    try {
      const std::uint64_t psize = fs.size.at("particles");
      const std::string head = fs.prefix("particles", 1 << 20);  // the header is much shorter
      Reader pr(head, file, "particles", psize - head.size());
      const auto count = pr.get<std::uint64_t>();
      const auto nextra = pr.get<std::uint32_t>();
      pr.check_count(nextra, 12, "per-particle fields");
      std::size_t per = kCoreFields;
      for (std::uint32_t k = 0; k < nextra; ++k) {
        const std::string fname = pr.get_string();
        const auto ncomp = pr.get<std::uint32_t>();
        if (fname.empty() || ncomp < 1 || ncomp > 4096)
          throw bad("per-particle field " + std::to_string(k + 1) + " has no name or " +
                    std::to_string(ncomp) + " values (1..4096)");
        per += ncomp;
      }
      pr.check_count(count, per * sizeof(double), "particles");
      phead = head.substr(0, pr.position());
      records_at = pr.position();
      // every record's core values, checked before anything is applied
      // (layout: id type mask x(3) v(3) omega(3) f(3) torque(3) radius density rmass body image)
      std::vector<double> ids;
      ids.reserve(count);
      auto integral = [](double v, double lo, double hi) { return v >= lo && v <= hi && v == std::floor(v); };
      const std::size_t chunk = std::max<std::size_t>(1, kChunkBytes / (per * sizeof(double)));
      std::vector<double> block;
      for (std::uint64_t r = 0; r < count; ++r) {
        if (r % chunk == 0) {
          block.resize(static_cast<std::size_t>(std::min<std::uint64_t>(chunk, count - r)) * per);
          fs.read("particles", records_at + r * per * sizeof(double), block.size() * sizeof(double),
                  reinterpret_cast<char*>(block.data()));
        }
        const double* rec = &block[(r % chunk) * per];
        const std::string which = "particle record " + std::to_string(r + 1);
        for (int c = 0; c < kCoreFields; ++c)
          if (!std::isfinite(rec[c])) throw bad(which + " holds a value that is not a finite number");
        if (!integral(rec[0], 1.0, 9.0e15)) throw bad(which + " has the id " + fmt(rec[0]));
        if (!integral(rec[1], 1.0, ntypes))
          throw bad(which + " has the type " + fmt(rec[1]) + " (1.." + std::to_string(ntypes) + ")");
        if (!integral(rec[2], 0.0, 2147483647.0)) throw bad(which + " has the group mask " + fmt(rec[2]));
        if (!sph_file && !(rec[18] > 0.0 && rec[19] > 0.0 && rec[20] > 0.0))
          throw bad(which + " has a radius, density or mass that is not positive");
        // SPH particles: points (radius and density 0 until the pair style sets the radius)
        if (sph_file && !(rec[18] >= 0.0 && rec[19] >= 0.0 && rec[20] > 0.0))
          throw bad(which +
                    " (atom_style sph) has a negative radius or density or a mass that is not positive");
        if (!integral(rec[21], -1.0, 9.0e15)) throw bad(which + " has the body " + fmt(rec[21]));
        if (!integral(rec[22], -2147483648.0, 2147483647.0))
          throw bad(which + " has the image flags " + fmt(rec[22]));
        ids.push_back(rec[0]);
      }
      std::sort(ids.begin(), ids.end());
      if (std::adjacent_find(ids.begin(), ids.end()) != ids.end())
        throw bad("two particle records have the same id");
    } catch (const InputError& x) {
      problem = x.what();
    }
  }
  agree(e, problem);
  bcast_string(e.world, phead);
  // (checked on rank 0: the same header parses the same way everywhere)
  Reader pr(phead, file, "particles");
  const auto count = pr.get<std::uint64_t>();
  const auto nextra = pr.get<std::uint32_t>();
  std::vector<std::string> fnames(nextra);
  std::vector<int> fncomp(nextra);
  std::size_t per = kCoreFields;
  for (std::uint32_t k = 0; k < nextra; ++k) {
    fnames[k] = pr.get_string();
    fncomp[k] = static_cast<int>(pr.get<std::uint32_t>());
    per += fncomp[k];
  }

  // the contact history: checked on rank 0, sent out in chunks once every
  // rank knows its particles (below)
  std::uint64_t hist_n = 0;
  std::uint32_t hist_nv = 0;
  std::uint64_t hist_at = 0;  // rank 0: where the entries start in the section
  problem.clear();
  if (e.rank == 0 && fs.has("contact_history")) {
    try {
      const std::string head = fs.prefix("contact_history", 12);
      Reader hr(head, file, "contact_history", fs.size.at("contact_history") - head.size());
      hist_n = hr.get<std::uint64_t>();
      hist_nv = hr.get<std::uint32_t>();
      if (hist_nv > 4096)
        throw bad("contact history entries of " + std::to_string(hist_nv) + " values (0..4096)");
      hr.check_count(hist_n, 16 + hist_nv * sizeof(double), "contact history entries");
      hist_at = hr.position();
    } catch (const InputError& x) {
      problem = x.what();
    }
  }
  agree(e, problem);
  MPI_Bcast(&hist_n, 1, MPI_UINT64_T, 0, e.world);
  MPI_Bcast(&hist_nv, 1, MPI_UINT32_T, 0, e.world);
  // the fixes' states: parsed on rank 0 and sent one by one (no rank holds
  // the section and its parsed copy at once)
  std::map<std::string, Modify::RestartState> states;
  problem.clear();
  std::uint32_t nstates = 0;
  if (e.rank == 0 && fs.held("fixes")) {
    try {
      Reader fr(fs.small["fixes"], file, "fixes");
      nstates = fr.get<std::uint32_t>();
      for (std::uint32_t k = 0; k < nstates; ++k) {
        const std::string id = fr.get_string();
        Modify::RestartState st;
        st.style = fr.get_string();
        st.data = fr.get_string();
        states[id] = std::move(st);
      }
      nstates = static_cast<std::uint32_t>(states.size());
    } catch (const InputError& x) {
      problem = x.what();
    }
  }
  agree(e, problem);
  MPI_Bcast(&nstates, 1, MPI_UINT32_T, 0, e.world);
  {
    auto it = states.begin();
    for (std::uint32_t k = 0; k < nstates; ++k) {
      std::string id = e.rank == 0 ? it->first : std::string();
      bcast_string(e.world, id);
      Modify::RestartState& st = states[id];
      bcast_string(e.world, st.style);
      bcast_string(e.world, st.data);
      if (e.rank == 0) ++it;
    }
  }
  std::map<std::string, std::vector<double>> materials;
  if (sec.count("materials")) {
    Reader mr(sec["materials"], file, "materials");
    const auto nm = mr.get<std::uint32_t>();
    for (std::uint32_t k = 0; k < nm; ++k) {
      const std::string name = mr.get_string();
      const auto nvalues = mr.get<std::uint64_t>();
      mr.check_count(nvalues, sizeof(double), "material values");
      std::vector<double> values(nvalues);
      mr.get_doubles(values.data(), values.size());
      materials[name] = values;
    }
  }

  // ---- apply
  Domain& d = *e.domain;
  d.units = units;
  for (int k = 0; k < 3; ++k) {
    d.boundary[k] = {bnd[k][0], bnd[k].size() > 1 ? bnd[k][1] : bnd[k][0]};
    d.periodic[k] = bnd[k][0] == 'p';
  }
  d.set_box(minlo, minhi);
  d.boxlo = boxlo;
  d.boxhi = boxhi;
  d.prd = boxhi - boxlo;
  e.particles->ntypes = ntypes;
  Update& u = *e.update;
  u.ntimestep = step;
  u.atime = atime;
  u.atimestep = atimestep;
  u.dt = dt;
  e.force->newton_pair = need("newton", 1)[0] == "on";
  Neighbor& ne = *e.neighbor;
  ne.skin = skin_read;
  ne.every = static_cast<int>(neigh_int[0]);
  ne.delay = static_cast<int>(neigh_int[1]);
  ne.check = nb[3] == "1";
  ne.sort_every = static_cast<int>(neigh_int[3]);
  ne.sort_binsize = sort_binsize;
  for (const auto& gn : group_names)
    e.groups->names[gn.first] = gn.second;
  if (g.count("pair_style")) e.force->restart_pair_style = join(g["pair_style"]);
  // (files without these keys predate them: 3d, granular)
  d.dimension = g.count("dimension") && !g["dimension"].empty() && g["dimension"][0] == "2" ? 2 : 3;
  e.comm->setup(0.0);

  Particles& p = *e.particles;
  p.set_sph(sph_file);  // the file's atom style, whatever the script said before
  if (sph_file) {
    p.type_mass.assign(ntypes + 1, 0.0);
    if (g.count("type_mass"))
      for (int t = 1; t <= ntypes && t <= static_cast<int>(g["type_mass"].size()); ++t)
        p.type_mass[t] = pdouble(g["type_mass"][t - 1], "type_mass");
    if (g.count("sph_kernel") && !g["sph_kernel"].empty()) p.sph_kernel = g["sph_kernel"][0];
  }
  std::vector<int> field(nextra);
  for (std::uint32_t k = 0; k < nextra; ++k)
    field[k] = p.add_field(fnames[k], fncomp[k], false, true);
  // the stored forces (Update::kRestartForcesField), each particle's with it
  p.release_field(Update::kRestartForcesField);
  const int stored = p.add_field(Update::kRestartForcesField, Update::kRestartForceValues, false, true);
  p.extras[stored].restart = false;
  // the records in chunks of about 8 MB from rank 0; each rank keeps its own
  const std::size_t chunk = std::max<std::size_t>(1, (std::size_t{8} << 20) / (per * sizeof(double)));
  std::vector<double> chunk_records;
  for (std::uint64_t r0 = 0; r0 < count; r0 += chunk) {
    const std::size_t nrec = static_cast<std::size_t>(std::min<std::uint64_t>(chunk, count - r0));
    chunk_records.resize(nrec * per);
    if (e.rank == 0)
      fs.read("particles", records_at + r0 * per * sizeof(double), chunk_records.size() * sizeof(double),
              reinterpret_cast<char*>(chunk_records.data()));
    if (e.nprocs > 1)
      MPI_Bcast(chunk_records.data(), static_cast<int>(chunk_records.size()), MPI_DOUBLE, 0, e.world);
    for (std::size_t r = 0; r < nrec; ++r) {
      const double* rec = &chunk_records[r * per];
      const Vec3 x(rec[3], rec[4], rec[5]);
      if (e.comm->owner_of(x) != e.rank) continue;
      // record layout: id type mask x(3) v(3) omega(3) f(3) torque(3) radius density rmass body image
      const int i = p.add_local(static_cast<tagint>(rec[0]), static_cast<int>(rec[1]), x, rec[18], rec[19]);
      p.mask[i] = static_cast<int>(rec[2]);
      p.v[i] = Vec3(rec[6], rec[7], rec[8]);
      p.omega[i] = Vec3(rec[9], rec[10], rec[11]);
      p.f[i] = Vec3(rec[12], rec[13], rec[14]);
      p.torque[i] = Vec3(rec[15], rec[16], rec[17]);
      p.rmass[i] = rec[20];
      p.body[i] = static_cast<tagint>(rec[21]);
      p.image[i] = static_cast<int>(rec[22]);
      std::size_t m = kCoreFields;
      for (std::uint32_t k = 0; k < nextra; ++k) {
        double* dst = &p.extras[field[k]].data[static_cast<std::size_t>(i) * fncomp[k]];
        std::copy_n(rec + m, fncomp[k], dst);
        m += fncomp[k];
      }
      double* const s = &p.extras[stored].data[static_cast<std::size_t>(i) * Update::kRestartForceValues];
      std::copy_n(rec + 12, 6, s);
      s[6] = 1.0;
    }
  }
  p.natoms = u.count_global();
  // forces stored after particles were changed between runs are not those of
  // the stored state: the next run recomputes them
  if (!forces_current) p.release_field(Update::kRestartForcesField);
  e.update->restart_forces_natoms = p.natoms;
  u.forces_current = forces_current;
  // contact history: each rank keeps the contacts of its own particles, as
  // rows (a row travels with its particle when that moves before the pair
  // style takes the history)
  e.force->pending_history.reset();
  if (hist_n > 0) {
    std::unordered_set<tagint> own(p.id.begin(), p.id.begin() + p.nlocal);
    const std::size_t entry = 16 + hist_nv * sizeof(double);
    const std::size_t per_chunk = std::max<std::size_t>(1, (std::size_t{8} << 20) / entry);
    std::vector<double> kept = {0.0, static_cast<double>(hist_nv)};
    std::vector<char> bytes;
    std::vector<double> values(hist_nv);
    for (std::uint64_t c0 = 0; c0 < hist_n; c0 += per_chunk) {
      const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(per_chunk, hist_n - c0));
      bytes.resize(n * entry);
      if (e.rank == 0) fs.read("contact_history", hist_at + c0 * entry, bytes.size(), bytes.data());
      if (e.nprocs > 1) MPI_Bcast(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, 0, e.world);
      for (std::size_t c = 0; c < n; ++c) {
        std::int64_t ab[2];
        std::memcpy(ab, bytes.data() + c * entry, 16);
        if (!own.count(static_cast<tagint>(ab[0])) && !own.count(static_cast<tagint>(ab[1]))) continue;
        std::memcpy(values.data(), bytes.data() + c * entry + 16, hist_nv * sizeof(double));
        kept.push_back(static_cast<double>(ab[0]));
        kept.push_back(static_cast<double>(ab[1]));
        kept.insert(kept.end(), values.begin(), values.end());
        kept[0] += 1.0;
      }
    }
    auto pending = std::make_unique<ContactHistory>();
    pending->configure(static_cast<int>(hist_nv), std::vector<double>(hist_nv, 1.0));
    pending->unpack_all(kept, [&](tagint t) { return own.count(t) > 0; });
    e.force->pending_history = std::move(pending);
  }
  e.modify->restart_states = std::move(states);
  e.modify->restart_materials = std::move(materials);
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "Read restart file %s: %lld particles at step %lld, time %g s (written on %s rank(s))\n"
                "  %d by %d by %d MPI processor grid\n",
                file.c_str(), static_cast<long long>(p.natoms), static_cast<long long>(step), u.time(),
                g.count("written_on_ranks") ? g["written_on_ranks"][0].c_str() : "?", e.comm->procgrid[0],
                e.comm->procgrid[1], e.comm->procgrid[2]);
  e.logger->print(buf);
}

void cmd_write_restart(Engine& e, const Args& a) {
  require_args(a, 1, 1, "write_restart FILE");
  write_restart(e, expand_step(a[0], e.update->ntimestep));
}
void cmd_read_restart(Engine& e, const Args& a) {
  require_args(a, 1, 1, "read_restart FILE");
  read_restart(e, a[0]);
}
GRANARY_COMMAND("write_restart", cmd_write_restart);
GRANARY_COMMAND("read_restart", cmd_read_restart);

}  // namespace granary
