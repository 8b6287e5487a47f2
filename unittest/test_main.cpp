// Catch2 main shared by all test executables: MPI is initialised once around
// the whole session so that tests can create engines on MPI_COMM_WORLD.
#define CATCH_CONFIG_RUNNER
#include <mpi.h>

#include <cstdlib>

#include <catch2/catch.hpp>

int main(int argc, char** argv) {
  // The tests' VTK dumps load this build's VTK module (the test executables
  // are not in the folder of granary and granary_vtk.so); granary run by a
  // test inherits the setting.
  setenv("GRANARY_VTK_MODULE", GRANARY_VTK_MODULE_FILE, 0);
  MPI_Init(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  Catch::Session session;
  int rc = session.applyCommandLine(argc, argv);
  if (rc == 0) rc = session.run();
  // Every rank must agree on failure for mpiexec to report it.
  int all = 0;
  MPI_Allreduce(&rc, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return all;
}
