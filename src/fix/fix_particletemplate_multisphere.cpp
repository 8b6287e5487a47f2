#include "fix/fix_particletemplate_multisphere.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group particletemplate/multisphere SEED atom_type T density constant RHO nspheres N ntry M "
    "spheres file FILE [scale S] | spheres x1 y1 z1 r1 ... type MT [mass M] "
    "[inertia_tensor Ixx Ixy Ixz Iyy Iyz Izz] [use_volume | use_density]";

}  // namespace

void FixParticleTemplateMultisphere::read_file(const std::string& path, double scale,
                                               std::vector<double>& values) const {
  // rank 0 reads, everyone gets the text (and the same error)
  std::string text, problem;
  if (engine_.rank == 0) {
    std::ifstream in(path);
    if (!in) {
      problem = "cannot open sphere file '" + path + "'";
    } else {
      std::ostringstream os;
      os << in.rdbuf();
      text = os.str();
    }
  }
  for (std::string* s : {&text, &problem}) {
    unsigned long long n = s->size();
    MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, engine_.world);
    s->resize(n);
    if (n) MPI_Bcast(&(*s)[0], static_cast<int>(n), MPI_CHAR, 0, engine_.world);
  }
  const std::string what = "fix " + id + " particletemplate/multisphere";
  if (!problem.empty()) throw InputError(what + ": " + problem);
  std::istringstream lines(text);
  std::string line;
  int lineno = 0;
  while (std::getline(lines, line)) {
    ++lineno;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    std::string w;
    int count = 0;
    const std::string where = what + ": sphere file '" + path + "' line " + std::to_string(lineno) + ": ";
    while (words >> w) {
      double v = 0.0;
      try {
        std::size_t used = 0;
        v = std::stod(w, &used);
        if (used != w.size()) throw std::invalid_argument(w);
      } catch (const std::exception&) {
        throw InputError(where + "'" + w + "' is not a number (expected lines 'x y z r')");
      }
      if (!std::isfinite(v))
        throw InputError(where + "'" + w + "' is not a finite number (expected lines 'x y z r')");
      values.push_back(v * scale);
      ++count;
    }
    if (count != 0 && count != 4) {
      throw InputError(where + "holds " + std::to_string(count) +
                       " numbers; each line holds one sphere, 'x y z r'");
    }
  }
}

FixParticleTemplateMultisphere::FixParticleTemplateMultisphere(Engine& engine, const Args& args)
    : FixParticleTemplate(engine, args) {
  const std::string what = "fix " + id + " particletemplate/multisphere";
  if (args.size() < 4) throw InputError(std::string("wrong number of arguments; usage: ") + kUsage);
  seed = parse_seed(what);

  double density = 1.0, mass_given = -1.0, volume_limit = 0.0;
  long long nspheres = -1, ntry = 1000000;
  bool have_spheres = false, use_density = false, have_tensor = false;
  std::vector<double> values;  // x y z r per sphere
  Eigen::Matrix3d tensor = Eigen::Matrix3d::Zero();
  for (std::size_t k = 4; k < args.size(); ++k) {
    if (parse_common_keyword(k, what, density)) continue;
    const std::string& w = args[k];
    auto value = [&](const char* name) -> const std::string& {
      if (k + 1 >= args.size()) throw InputError(what + ": keyword '" + w + "' needs " + name);
      return args[++k];
    };
    if (w == "nspheres") {
      nspheres = parse_int(value("a count"), what + " nspheres");
      if (nspheres < 1) throw InputError(what + ": nspheres must be at least 1");
    } else if (w == "ntry") {
      ntry = parse_int(value("a count"), what + " ntry");
      if (ntry < 1000) throw InputError(what + ": ntry must be at least 1000 (1e6 is typical)");
    } else if (w == "spheres") {
      if (k + 1 < args.size() && args[k + 1] == "file") {
        ++k;
        const std::string path = value("a file name");
        double scale = 1.0;
        if (k + 1 < args.size() && args[k + 1] == "scale") {
          ++k;
          scale = parse_double(value("a factor"), what + " scale");
          if (!(scale > 0.0)) throw InputError(what + ": scale must be positive");
        }
        read_file(path, scale, values);
        if (values.size() % 4 != 0) {
          throw InputError(what + ": sphere file '" + path + "' holds " + std::to_string(values.size()) +
                           " numbers, not a multiple of 4 (lines 'x y z r')");
        }
        if (nspheres < 0) nspheres = static_cast<long long>(values.size() / 4);
        if (static_cast<long long>(values.size() / 4) != nspheres) {
          throw InputError(what + ": sphere file '" + path + "' holds " + std::to_string(values.size() / 4) +
                           " spheres but nspheres is " + std::to_string(nspheres));
        }
      } else {
        if (nspheres < 0)
          throw InputError(what + ": give nspheres N before the inline 'spheres x1 y1 z1 r1 ...'");
        if (k + 4 * nspheres >= args.size()) {
          throw InputError(what + ": spheres needs " + std::to_string(4 * nspheres) +
                           " numbers (x y z r for each of " + std::to_string(nspheres) + " spheres)");
        }
        for (long long m = 0; m < 4 * nspheres; ++m) {
          values.push_back(parse_double(args[++k], what + " spheres"));
          if (!std::isfinite(values.back()))
            throw InputError(what + ": spheres: '" + args[k] + "' is not a finite number");
        }
      }
      have_spheres = true;
    } else if (w == "type") {
      clump_type = static_cast<int>(parse_int(value("a type"), what + " type"));
      if (clump_type < 1) throw InputError(what + ": the multisphere type must be at least 1");
    } else if (w == "mass") {
      mass_given = parse_double(value("a value"), what + " mass");
      if (!(mass_given > 0.0)) throw InputError(what + ": mass must be positive");
    } else if (w == "inertia_tensor") {
      const int idx[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
      for (const auto& ij : idx) {
        const double v = parse_double(value("six values Ixx Ixy Ixz Iyy Iyz Izz"), what + " inertia_tensor");
        tensor(ij[0], ij[1]) = tensor(ij[1], ij[0]) = v;
      }
      have_tensor = true;
    } else if (w == "use_volume") {
      use_density = false;
    } else if (w == "use_density") {
      use_density = true;
    } else if (w == "volume_limit") {
      volume_limit = parse_double(value("a value"), what + " volume_limit");
      if (!(volume_limit >= 0.0)) throw InputError(what + ": volume_limit must not be negative");
    } else if (w == "relative") {
      if (parse_bool(value("yes or no"), what + " relative")) {
        throw InputError(what + ": relative yes (sizes relative to a reference radius) is not supported");
      }
    } else if (w == "fflag" || w == "tflag") {
      for (int d = 0; d < 3; ++d) {
        if (value("three values on|off") != "on") {
          throw InputError(what + ": " + w +
                           " with 'off' components (constrained bodies) is not supported; "
                           "use 'on on on' or leave the keyword out");
        }
      }
    } else {
      const std::string hint =
          did_you_mean(w, {"atom_type", "density", "nspheres", "ntry", "spheres", "type", "mass",
                           "inertia_tensor", "use_volume", "use_density", "volume_limit"});
      throw InputError(what + ": unknown keyword '" + w + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; usage: " + kUsage);
    }
  }
  if (!have_spheres)
    throw InputError(what + " needs 'spheres file FILE' or 'spheres x1 y1 z1 r1 ...'; usage: " + kUsage);

  const int n = static_cast<int>(values.size() / 4);
  std::vector<double> radii(n);
  centres_.resize(n);
  for (int k = 0; k < n; ++k) {
    centres_[k] = Vec3(values[4 * k], values[4 * k + 1], values[4 * k + 2]);
    radii[k] = values[4 * k + 3];
    if (!(radii[k] > 0.0)) {
      throw InputError(what + ": sphere " + std::to_string(k + 1) + " has radius " + format_number(radii[k]) +
                       "; radii must be positive");
    }
  }
  try {
    props_ = sphere_union_properties(centres_, radii, ntry, static_cast<std::uint64_t>(seed));
  } catch (const std::invalid_argument& e) {
    throw InputError(what + ": the clump's spheres: " + e.what());
  }

  // mass, density and volume (LIGGGHTS: mass with use_volume sets the density,
  // with use_density the volume)
  double volume = props_.volume, mass = density * volume;
  if (mass_given > 0.0) {
    mass = mass_given;
    if (use_density)
      volume = mass / density;
    else
      density = mass / volume;
  }
  if (volume < volume_limit) {
    throw InputError(what + ": the clump volume " + format_number(volume) + " m^3 is below volume_limit " +
                     format_number(volume_limit) +
                     " (check the units: coordinates and radii are in m, use scale), or lower volume_limit");
  }
  Eigen::Matrix3d inertia = (mass / props_.volume) * props_.inertia;
  if (have_tensor) inertia = tensor;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(inertia);
  Vec3 moments = eig.eigenvalues();
  axes_ = eig.eigenvectors();
  if (axes_.determinant() < 0.0) axes_.col(2) *= -1.0;
  if (!(moments[0] > 0.0)) throw InputError(what + ": the inertia tensor is not positive definite");
  centre_ = props_.centre;

  particle_.type = atom_type;
  particle_.density = density;
  particle_.mass = mass;
  particle_.volume = volume;
  particle_.inertia = moments;
  particle_.multisphere = true;
  particle_.radii = radii;
  particle_.frame = Eigen::Quaterniond(axes_);
  particle_.offsets.resize(n);
  particle_.bounding_radius = 0.0;
  for (int k = 0; k < n; ++k) {
    particle_.offsets[k] = axes_.transpose() * (centres_[k] - centre_);
    particle_.bounding_radius = std::max(particle_.bounding_radius, particle_.offsets[k].norm() + radii[k]);
  }

  std::ostringstream log;
  log << what << ": " << n << " spheres, volume " << format_number(volume) << " m^3 (relative error "
      << format_number(props_.relative_volume_error()) << ", " << props_.samples << " samples), mass "
      << format_number(mass) << " kg, principal moments " << format_number(moments[0]) << " "
      << format_number(moments[1]) << " " << format_number(moments[2]) << " kg m^2 (relative error "
      << format_number(props_.relative_inertia_error()) << "), bounding radius "
      << format_number(particle_.bounding_radius) << " m, centre of mass (" << format_number(centre_[0])
      << ", " << format_number(centre_[1]) << ", " << format_number(centre_[2]) << ") m in the input frame\n";
  engine.logger->print(log.str());
}

void FixParticleTemplateMultisphere::init() {
  if (atom_type > engine_.particles->ntypes) {
    throw InputError("fix " + id + " particletemplate/multisphere: atom_type " + std::to_string(atom_type) +
                     " is outside 1.." + std::to_string(engine_.particles->ntypes) +
                     " (the number of atom types given to create_box)");
  }
}

GRANARY_FIX_STYLE("particletemplate/multisphere", FixParticleTemplateMultisphere);

}  // namespace granary
