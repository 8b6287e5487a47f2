// Named groups of particles (bits of the per-particle mask), the `group`
// command and the group functions count/mass/xcm/vcm/bound.
#include "domain/groups.h"

#include <mpi.h>

#include <algorithm>
#include <cctype>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "core/modify.h"
#include "particles/particles.h"

namespace granary {

namespace {

constexpr double kBig = 1.0e20;

const char* kUsage =
    "group ID region REGION | type T... | id I... | type|id <|<=|>|>=|==|!= N | "
    "type|id <> LO HI | subtract G1 G2... | union G1... | intersect G1 G2... | delete | clear | empty";

/// A selection of integer values (types or ids) given as a list of values and
/// ranges ("3", "1*4", "*2", "5*") or a comparison ("< 3", "<> 2 7").
class IntSelection {
 public:
  IntSelection(const Args& words, std::size_t first, long long lo_all, long long hi_all,
               const std::string& what) {
    if (first >= words.size()) {
      throw InputError("group " + what + " needs at least one value or range");
    }
    const std::string& op = words[first];
    if (op == "<" || op == "<=" || op == ">" || op == ">=" || op == "==" || op == "!=") {
      if (words.size() != first + 2) {
        throw InputError("group " + what + " " + op + " takes exactly one value");
      }
      const long long v = parse_int(words[first + 1], "the " + what + " bound");
      if (op == "<") ranges_.push_back({lo_all, v - 1});
      if (op == "<=") ranges_.push_back({lo_all, v});
      if (op == ">") ranges_.push_back({v + 1, hi_all});
      if (op == ">=") ranges_.push_back({v, hi_all});
      if (op == "==") ranges_.push_back({v, v});
      if (op == "!=") {
        ranges_.push_back({lo_all, v - 1});
        ranges_.push_back({v + 1, hi_all});
      }
      return;
    }
    if (op == "<>") {
      if (words.size() != first + 3) {
        throw InputError("group " + what + " <> takes exactly two values: LO HI");
      }
      const long long a = parse_int(words[first + 1], "the lower " + what + " bound");
      const long long b = parse_int(words[first + 2], "the upper " + what + " bound");
      if (a > b) throw InputError("group " + what + " <> LO HI needs LO <= HI");
      ranges_.push_back({a, b});
      return;
    }
    for (std::size_t k = first; k < words.size(); ++k) {
      const std::string& w = words[k];
      const auto star = w.find('*');
      long long a, b;
      if (star == std::string::npos) {
        a = b = parse_int(w, "a " + what);
      } else {
        const std::string sa = w.substr(0, star), sb = w.substr(star + 1);
        a = sa.empty() ? lo_all : parse_int(sa, "a " + what + " range");
        b = sb.empty() ? hi_all : parse_int(sb, "a " + what + " range");
        if (a > b) throw InputError("empty " + what + " range '" + w + "'; write it as LO*HI");
      }
      ranges_.push_back({a, b});
    }
  }

  bool contains(long long v) const {
    for (const auto& r : ranges_)
      if (v >= r.first && v <= r.second) return true;
    return false;
  }

 private:
  std::vector<std::pair<long long, long long>> ranges_;
};

void check_group_name(const std::string& name) {
  if (name.empty()) throw InputError("group names must not be empty");
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) {
      throw InputError("group ID '" + name + "' may use only letters, digits and underscores");
    }
  }
}

}  // namespace

Groups::Groups(Engine& engine) : engine_(engine) {
  names[0] = "all";
}

int Groups::find(const std::string& name) const {
  for (int g = 0; g < kMaxGroups; ++g)
    if (!names[g].empty() && names[g] == name) return g;
  return -1;
}

int Groups::find_or_error(const std::string& name, const std::string& what) const {
  const int g = find(name);
  if (g >= 0) return g;
  std::vector<std::string> known;
  for (const auto& n : names)
    if (!n.empty()) known.push_back(n);
  const std::string hint = did_you_mean(name, known);
  throw InputError("unknown group '" + name + "' in " + what +
                   (hint.empty() ? "; define it first with the group command" : "; " + hint));
}

int Groups::find_or_create(const std::string& name) {
  const int g = find(name);
  if (g >= 0) return g;
  check_group_name(name);
  for (int k = 1; k < kMaxGroups; ++k) {
    if (names[k].empty()) {
      names[k] = name;
      return k;
    }
  }
  throw InputError("cannot create group '" + name + "': all " + std::to_string(kMaxGroups) +
                   " groups are in use; delete unused ones with group ID delete");
}

void Groups::command(const Args& args) {
  if (args.size() < 2) throw InputError("usage: " + std::string(kUsage));
  const std::string& name = args[0];
  const std::string& style = args[1];
  Particles& p = *engine_.particles;

  if (style == "delete") {
    require_args(args, 2, 2, "group ID delete");
    const int g = find_or_error(name, "group delete");
    if (g == 0) throw InputError("group all cannot be deleted");
    const std::string user = engine_.modify->group_user(g);
    if (!user.empty()) {
      const bool fix = user.rfind("fix ", 0) == 0;
      throw InputError("cannot delete group " + name + ": " + user + " uses it; " +
                       (fix ? "unfix" : "uncompute") + " it first");
    }
    const int keep = ~bitmask(g);
    for (int i = 0; i < p.size(); ++i)
      p.mask[i] &= keep;
    names[g].clear();
    return;
  }

  if (style == "clear") {
    require_args(args, 2, 2, "group ID clear");
    const int g = find_or_error(name, "group clear");
    if (g == 0) throw InputError("group all cannot be cleared");
    const int keep = ~bitmask(g);
    for (int i = 0; i < p.size(); ++i)
      p.mask[i] &= keep;
    return;
  }

  static const std::vector<std::string> styles = {"region",    "type",   "id",    "subtract", "union",
                                                  "intersect", "delete", "clear", "empty"};
  if (std::find(styles.begin(), styles.end(), style) == styles.end()) {
    const std::string hint = did_you_mean(style, styles);
    throw InputError("unknown group style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                     "; usage: " + kUsage);
  }

  // Resolve every input before creating the group, so a failing command
  // leaves no half-made group behind.
  std::vector<int> members;  // bits of the "other" groups of subtract/union/intersect
  const Region* region = nullptr;
  std::unique_ptr<IntSelection> selection;
  if (style == "empty") {
    require_args(args, 2, 2, "group ID empty");
  } else if (style == "region") {
    require_args(args, 3, 3, "group ID region REGION");
    region = engine_.domain->region_or_error(args[2], "group " + name);
  } else if (style == "type") {
    selection = std::make_unique<IntSelection>(args, 2, 1, std::max(1, p.ntypes), "type");
  } else if (style == "id") {
    selection = std::make_unique<IntSelection>(args, 2, 1, std::numeric_limits<long long>::max() / 2, "id");
  } else {
    const std::size_t need = style == "union" ? 3 : 4;
    if (args.size() < need) {
      throw InputError("group " + style + " needs " +
                       (need == 3 ? "at least one group" : "at least two groups") + "; usage: group ID " +
                       style + " G1 G2 ...");
    }
    for (std::size_t k = 2; k < args.size(); ++k) {
      members.push_back(bitmask(find_or_error(args[k], "group " + name + " " + style)));
    }
  }

  const int g = find_or_create(name);
  const int bit = bitmask(g);
  const int n = p.nlocal;
  if (style == "region") {
    for (int i = 0; i < n; ++i)
      if (region->match(p.x[i])) p.mask[i] |= bit;
  } else if (style == "type") {
    for (int i = 0; i < n; ++i)
      if (selection->contains(p.type[i])) p.mask[i] |= bit;
  } else if (style == "id") {
    for (int i = 0; i < n; ++i)
      if (selection->contains(static_cast<long long>(p.id[i]))) p.mask[i] |= bit;
  } else if (style == "subtract") {
    for (int i = 0; i < n; ++i) {
      bool in = (p.mask[i] & members[0]) != 0;
      for (std::size_t k = 1; in && k < members.size(); ++k)
        in = (p.mask[i] & members[k]) == 0;
      if (in) p.mask[i] |= bit;
    }
  } else if (style == "union") {
    for (int i = 0; i < n; ++i) {
      for (int m : members) {
        if (p.mask[i] & m) {
          p.mask[i] |= bit;
          break;
        }
      }
    }
  } else if (style == "intersect") {
    for (int i = 0; i < n; ++i) {
      bool in = true;
      for (std::size_t k = 0; in && k < members.size(); ++k)
        in = (p.mask[i] & members[k]) != 0;
      if (in) p.mask[i] |= bit;
    }
  }
  // Ghost copies get the new masks when the ghosts are next rebuilt (run setup).
  const double total = count(g);
  std::ostringstream msg;
  msg << static_cast<long long>(total) << " atoms in group " << name << "\n";
  engine_.logger->print(msg.str());
}

double Groups::count(int igroup, const Region* region) const {
  const Particles& p = *engine_.particles;
  const int bit = bitmask(igroup);
  long long local = 0;
  for (int i = 0; i < p.nlocal; ++i) {
    if ((p.mask[i] & bit) && (!region || region->match(p.x[i]))) ++local;
  }
  long long all = 0;
  MPI_Allreduce(&local, &all, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
  return static_cast<double>(all);
}

double Groups::mass(int igroup, const Region* region) const {
  const Particles& p = *engine_.particles;
  const int bit = bitmask(igroup);
  double local = 0.0;
  for (int i = 0; i < p.nlocal; ++i) {
    if ((p.mask[i] & bit) && (!region || region->match(p.x[i]))) local += p.rmass[i];
  }
  double all = 0.0;
  MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
  return all;
}

Vec3 Groups::unwrapped(int i) const {
  const Particles& p = *engine_.particles;
  const Domain& dom = *engine_.domain;
  int ix, iy, iz;
  Particles::image_unpack(p.image[i], ix, iy, iz);
  // periodic images put back where the particle travelled
  return p.x[i] + Vec3(ix * dom.prd[0], iy * dom.prd[1], iz * dom.prd[2]);
}

Vec3 Groups::omega(int igroup, const Vec3& xcm) const {
  const Particles& p = *engine_.particles;
  const int bit = bitmask(igroup);
  double local[12] = {0};  // L (3), inertia tensor (9)
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & bit)) continue;
    const Vec3 r = unwrapped(i) - xcm;
    const double m = p.rmass[i];
    const Vec3 L = m * r.cross(p.v[i]);
    const Eigen::Matrix3d I = m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
    for (int d = 0; d < 3; ++d)
      local[d] += L[d];
    for (int q = 0; q < 9; ++q)
      local[3 + q] += I(q / 3, q % 3);
  }
  double all[12];
  MPI_Allreduce(local, all, 12, MPI_DOUBLE, MPI_SUM, engine_.world);
  const Vec3 L(all[0], all[1], all[2]);
  Eigen::Matrix3d I;
  for (int q = 0; q < 9; ++q)
    I(q / 3, q % 3) = all[3 + q];
  // omega = I^-1 L, restricted to the directions with inertia
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
  const double lmax = eig.eigenvalues().maxCoeff();
  Vec3 omega = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    const double lam = eig.eigenvalues()[k];
    if (lam > 1.0e-12 * lmax && lam > 0.0) {
      const Vec3 ev = eig.eigenvectors().col(k);
      omega += ev * (ev.dot(L) / lam);
    }
  }
  return omega;
}

Vec3 Groups::xcm(int igroup, const Region* region) const {
  const Particles& p = *engine_.particles;
  const int bit = bitmask(igroup);
  double local[4] = {0, 0, 0, 0};
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & bit) || (region && !region->match(p.x[i]))) continue;
    const Vec3 xu = unwrapped(i);
    const double m = p.rmass[i];
    for (int d = 0; d < 3; ++d)
      local[d] += m * xu[d];
    local[3] += m;
  }
  double all[4];
  MPI_Allreduce(local, all, 4, MPI_DOUBLE, MPI_SUM, engine_.world);
  if (all[3] <= 0.0) return Vec3::Zero();
  return Vec3(all[0], all[1], all[2]) / all[3];
}

Vec3 Groups::vcm(int igroup, const Region* region) const {
  const Particles& p = *engine_.particles;
  const int bit = bitmask(igroup);
  double local[4] = {0, 0, 0, 0};
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & bit) || (region && !region->match(p.x[i]))) continue;
    const double m = p.rmass[i];
    for (int d = 0; d < 3; ++d)
      local[d] += m * p.v[i][d];
    local[3] += m;
  }
  double all[4];
  MPI_Allreduce(local, all, 4, MPI_DOUBLE, MPI_SUM, engine_.world);
  if (all[3] <= 0.0) return Vec3::Zero();
  return Vec3(all[0], all[1], all[2]) / all[3];
}

void Groups::bounds(int igroup, Vec3& lo, Vec3& hi, const Region* region) const {
  const Particles& p = *engine_.particles;
  const int bit = bitmask(igroup);
  // -min and max in one MAX reduction; an empty group gives lo = +BIG, hi = -BIG (as LAMMPS)
  double local[6];
  for (double& v : local)
    v = -kBig;
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & bit) || (region && !region->match(p.x[i]))) continue;
    for (int d = 0; d < 3; ++d) {
      local[d] = std::max(local[d], -p.x[i][d]);
      local[d + 3] = std::max(local[d + 3], p.x[i][d]);
    }
  }
  double all[6];
  MPI_Allreduce(local, all, 6, MPI_DOUBLE, MPI_MAX, engine_.world);
  for (int d = 0; d < 3; ++d) {
    lo[d] = -all[d];
    hi[d] = all[d + 3];
  }
}

namespace {
void cmd_group(Engine& engine, const Args& args) {
  engine.groups->command(args);
}
}  // namespace

GRANARY_COMMAND("group", cmd_group);

}  // namespace granary
