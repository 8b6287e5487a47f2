/* Time spent inside blocking MPI calls, per rank: a library for LD_PRELOAD
 * built on the MPI profiling interface (each MPI_X calls PMPI_X and adds the
 * wall time between entry and return to X's total). At MPI_Finalize every
 * rank writes one line to standard error:
 *
 *   mpi_times rank R: NAME CALLS SECONDS; NAME CALLS SECONDS; ...
 *
 * for the calls it made at least once. The time of a blocking call is the
 * transfer and the wait for the partner ranks; non-blocking calls return at
 * once and their time shows in the MPI_Wait/MPI_Waitall that completes them.
 * Used by `tools/bench.py --mpi-times`, which builds it with mpicc:
 *
 *   mpicc -O2 -shared -fPIC tools/mpi_times.c -o libmpi_times.so
 *   mpirun -np 2 -x LD_PRELOAD=$PWD/libmpi_times.so build/granary -in in.script
 */
#include <mpi.h>
#include <stdio.h>

enum {
  kSend, kRecv, kSendrecv, kWait, kWaitall, kProbe, kBarrier, kBcast, kReduce, kAllreduce,
  kAllgather, kAllgatherv, kGather, kGatherv, kScatter, kScatterv, kAlltoall, kAlltoallv, kScan,
  kExscan, kCount
};
static const char* const kNames[kCount] = {
    "Send",      "Recv",       "Sendrecv", "Wait",    "Waitall",  "Probe",    "Barrier",
    "Bcast",     "Reduce",     "Allreduce", "Allgather", "Allgatherv", "Gather", "Gatherv",
    "Scatter",   "Scatterv",   "Alltoall", "Alltoallv", "Scan",     "Exscan"};
static double seconds[kCount];
static long calls[kCount];

#define TIMED(K, CALL)                  \
  do {                                  \
    const double t0_ = PMPI_Wtime();    \
    const int r_ = CALL;                \
    seconds[K] += PMPI_Wtime() - t0_;   \
    ++calls[K];                         \
    return r_;                          \
  } while (0)

int MPI_Send(const void* b, int c, MPI_Datatype t, int dest, int tag, MPI_Comm comm) {
  TIMED(kSend, PMPI_Send(b, c, t, dest, tag, comm));
}
int MPI_Recv(void* b, int c, MPI_Datatype t, int src, int tag, MPI_Comm comm, MPI_Status* st) {
  TIMED(kRecv, PMPI_Recv(b, c, t, src, tag, comm, st));
}
int MPI_Sendrecv(const void* sb, int sc, MPI_Datatype st, int dest, int stag, void* rb, int rc,
                 MPI_Datatype rt, int src, int rtag, MPI_Comm comm, MPI_Status* status) {
  TIMED(kSendrecv, PMPI_Sendrecv(sb, sc, st, dest, stag, rb, rc, rt, src, rtag, comm, status));
}
int MPI_Wait(MPI_Request* req, MPI_Status* st) { TIMED(kWait, PMPI_Wait(req, st)); }
int MPI_Waitall(int n, MPI_Request reqs[], MPI_Status sts[]) {
  TIMED(kWaitall, PMPI_Waitall(n, reqs, sts));
}
int MPI_Probe(int src, int tag, MPI_Comm comm, MPI_Status* st) {
  TIMED(kProbe, PMPI_Probe(src, tag, comm, st));
}
int MPI_Barrier(MPI_Comm comm) { TIMED(kBarrier, PMPI_Barrier(comm)); }
int MPI_Bcast(void* b, int c, MPI_Datatype t, int root, MPI_Comm comm) {
  TIMED(kBcast, PMPI_Bcast(b, c, t, root, comm));
}
int MPI_Reduce(const void* sb, void* rb, int c, MPI_Datatype t, MPI_Op op, int root, MPI_Comm comm) {
  TIMED(kReduce, PMPI_Reduce(sb, rb, c, t, op, root, comm));
}
int MPI_Allreduce(const void* sb, void* rb, int c, MPI_Datatype t, MPI_Op op, MPI_Comm comm) {
  TIMED(kAllreduce, PMPI_Allreduce(sb, rb, c, t, op, comm));
}
int MPI_Allgather(const void* sb, int sc, MPI_Datatype st, void* rb, int rc, MPI_Datatype rt,
                  MPI_Comm comm) {
  TIMED(kAllgather, PMPI_Allgather(sb, sc, st, rb, rc, rt, comm));
}
int MPI_Allgatherv(const void* sb, int sc, MPI_Datatype st, void* rb, const int rcs[], const int displs[],
                   MPI_Datatype rt, MPI_Comm comm) {
  TIMED(kAllgatherv, PMPI_Allgatherv(sb, sc, st, rb, rcs, displs, rt, comm));
}
int MPI_Gather(const void* sb, int sc, MPI_Datatype st, void* rb, int rc, MPI_Datatype rt, int root,
               MPI_Comm comm) {
  TIMED(kGather, PMPI_Gather(sb, sc, st, rb, rc, rt, root, comm));
}
int MPI_Gatherv(const void* sb, int sc, MPI_Datatype st, void* rb, const int rcs[], const int displs[],
                MPI_Datatype rt, int root, MPI_Comm comm) {
  TIMED(kGatherv, PMPI_Gatherv(sb, sc, st, rb, rcs, displs, rt, root, comm));
}
int MPI_Scatter(const void* sb, int sc, MPI_Datatype st, void* rb, int rc, MPI_Datatype rt, int root,
                MPI_Comm comm) {
  TIMED(kScatter, PMPI_Scatter(sb, sc, st, rb, rc, rt, root, comm));
}
int MPI_Scatterv(const void* sb, const int scs[], const int displs[], MPI_Datatype st, void* rb, int rc,
                 MPI_Datatype rt, int root, MPI_Comm comm) {
  TIMED(kScatterv, PMPI_Scatterv(sb, scs, displs, st, rb, rc, rt, root, comm));
}
int MPI_Alltoall(const void* sb, int sc, MPI_Datatype st, void* rb, int rc, MPI_Datatype rt,
                 MPI_Comm comm) {
  TIMED(kAlltoall, PMPI_Alltoall(sb, sc, st, rb, rc, rt, comm));
}
int MPI_Alltoallv(const void* sb, const int scs[], const int sdispls[], MPI_Datatype st, void* rb,
                  const int rcs[], const int rdispls[], MPI_Datatype rt, MPI_Comm comm) {
  TIMED(kAlltoallv, PMPI_Alltoallv(sb, scs, sdispls, st, rb, rcs, rdispls, rt, comm));
}
int MPI_Scan(const void* sb, void* rb, int c, MPI_Datatype t, MPI_Op op, MPI_Comm comm) {
  TIMED(kScan, PMPI_Scan(sb, rb, c, t, op, comm));
}
int MPI_Exscan(const void* sb, void* rb, int c, MPI_Datatype t, MPI_Op op, MPI_Comm comm) {
  TIMED(kExscan, PMPI_Exscan(sb, rb, c, t, op, comm));
}

int MPI_Finalize(void) {
  int rank = 0, k;
  char line[2048];
  int len;
  PMPI_Comm_rank(MPI_COMM_WORLD, &rank);
  len = snprintf(line, sizeof line, "mpi_times rank %d:", rank);
  for (k = 0; k < kCount; ++k) {
    if (calls[k] == 0) continue;
    len += snprintf(line + len, sizeof line - (size_t)len, " %s %ld %.6f;", kNames[k], calls[k], seconds[k]);
  }
  fprintf(stderr, "%s\n", line);
  fflush(stderr);
  return PMPI_Finalize();
}
