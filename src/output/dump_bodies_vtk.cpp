#include "output/dump_bodies_vtk.h"

#include <mpi.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkTypeInt64Array.h>
#include <vtkXMLPolyDataWriter.h>

#include <cstdio>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "output/vtk_module.h"
#include "core/update.h"
#include "particles/clumps.h"
#include "core/modify.h"
#include "output/dump_custom.h"
#include "particles/particles.h"
#include "output/vtk_frame.h"

namespace granary {

DumpBodiesVTK::DumpBodiesVTK(Engine& engine, const Args& args) : Dump(engine, args) {
  if (args.size() > 5) {
    throw InputError("dump " + id + ": bodies/vtk takes no fields (it writes every body's state), got '" +
                     args[5] + "'");
  }
  if (vtkio::extension(filename) != ".vtp") {
    throw InputError("dump " + id + ": bodies/vtk needs a file name ending in .vtp, got '" + filename + "'");
  }
  if (filename.find('%') != std::string::npos) {
    throw InputError("dump " + id +
                     ": bodies/vtk writes one file per frame on rank 0; '%' is not allowed in '" + filename +
                     "'");
  }
  dumpio::check_directory(engine.world, filename, "dump " + id);
  pvd_.path = vtkio::pvd_name(filename, id);
}

int DumpBodiesVTK::modify_param(const Args& args, std::size_t k) {
  const std::string& key = args[k];
  const std::string where = "dump_modify " + id + " " + key;
  if (const int used = options_.parse(args, k, where)) return used;
  if (const int used = dumpio::parse_pvd(engine_.world, args, k, where, false, pvd_.path)) {
    pvd_.clear();
    return used;
  }
  return 0;
}

Clumps& DumpBodiesVTK::multisphere() const {
  Clumps* ms = engine_.clumps;
  if (!ms) {
    throw InputError("dump " + id +
                     ": bodies/vtk writes the clumps of fix multisphere, but no fix multisphere "
                     "is defined");
  }
  return *ms;
}

void DumpBodiesVTK::init() {
  multisphere();
}

std::string DumpBodiesVTK::write_frame(const std::string& frame, const std::vector<char>& selected) {
  const Clumps& ms = multisphere();
  const Bodies& B = ms.bodies();
  std::vector<int> list;
  for (int b = 0; b < B.size(); ++b)
    if (selected[b]) list.push_back(b);
  const vtkIdType n = static_cast<vtkIdType>(list.size());

  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
  conn->SetNumberOfValues(n);
  auto cells = vtkSmartPointer<vtkCellArray>::New();

  auto ids = vtkio::named_array<vtkTypeInt64Array>("id", 1, n);
  auto types = vtkio::named_array<vtkIntArray>("type", 1, n);
  auto mass = vtkio::named_array<vtkDoubleArray>("mass", 1, n);
  auto quat = vtkio::named_array<vtkDoubleArray>("quaternion", 4, n);
  auto axis = vtkio::named_array<vtkDoubleArray>("long_axis", 3, n);
  auto vel = vtkio::named_array<vtkDoubleArray>("velocity", 3, n);
  auto omega = vtkio::named_array<vtkDoubleArray>("angular_velocity", 3, n);
  auto nsph = vtkio::named_array<vtkIntArray>("nspheres", 1, n);
  // the component names ParaView shows for the quaternion
  const char* qnames[4] = {"w", "x", "y", "z"};
  for (int c = 0; c < 4; ++c)
    quat->SetComponentName(c, qnames[c]);

  for (vtkIdType k = 0; k < n; ++k) {
    const int b = list[k];
    const Vec3 x = ms.wrapped_centre(b);
    points->SetPoint(k, x[0], x[1], x[2]);
    conn->SetValue(k, k);
    ids->SetValue(k, B.tag[b]);
    types->SetValue(k, B.type[b]);
    mass->SetValue(k, B.mass[b]);
    const Eigen::Quaterniond& q = B.quat[b];
    const double qv[4] = {q.w(), q.x(), q.y(), q.z()};
    quat->SetTypedTuple(k, qv);
    // body axis x is the principal axis of the smallest moment (the long axis)
    const Vec3 a = q * Vec3(1.0, 0.0, 0.0);
    axis->SetTypedTuple(k, a.data());
    vel->SetTypedTuple(k, B.vcm[b].data());
    omega->SetTypedTuple(k, B.omega[b].data());
    nsph->SetValue(k, B.nspheres[b]);
  }
  cells->SetData(1, conn);

  auto ds = vtkSmartPointer<vtkPolyData>::New();
  ds->SetPoints(points);
  ds->SetVerts(cells);
  for (vtkDataArray* a : std::initializer_list<vtkDataArray*>{ids, types, mass, quat, axis, vel, omega, nsph})
    ds->GetPointData()->AddArray(a);
  return vtkio::write_polydata_frame(ds, frame, engine_.update->time(), engine_.update->ntimestep, options_,
                                     pvd_);
}

void DumpBodiesVTK::write() {
  Clumps& ms = multisphere();
  ms.sync_bodies();  // rank 0 writes every body
  const Bodies& B = ms.bodies();

  // a body belongs to the dump's group when one of its sub-spheres does
  std::vector<char> selected(B.size(), 1);
  if (groupbit != 1) {
    const Particles& p = *engine_.particles;
    std::vector<int> local(B.size(), 0), all(B.size(), 0);
    for (int i = 0; i < p.nlocal; ++i) {
      if (p.body[i] < 0 || !(p.mask[i] & groupbit)) continue;
      const int b = B.find(p.body[i]);
      if (b >= 0) local[b] = 1;
    }
    MPI_Allreduce(local.data(), all.data(), B.size(), MPI_INT, MPI_MAX, engine_.world);
    for (int b = 0; b < B.size(); ++b)
      selected[b] = static_cast<char>(all[b]);
  }

  std::string err;
  if (engine_.rank == 0)
    err = write_frame(dumpio::expand(filename, engine_.update->ntimestep, options_.pad), selected);
  err = dumpio::first_error(engine_.world, err);
  if (!err.empty()) throw RunError("dump " + id + ": " + err);
}

GRANARY_VTK_DUMP_STYLE("bodies/vtk", DumpBodiesVTK);

}  // namespace granary
