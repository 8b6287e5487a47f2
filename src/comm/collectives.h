// Gathering variable-length data from every rank, in rank order.
#pragma once

#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace granary {

template <class T>
MPI_Datatype mpi_type();
template <>
inline MPI_Datatype mpi_type<double>() {
  return MPI_DOUBLE;
}
template <>
inline MPI_Datatype mpi_type<long long>() {
  return MPI_LONG_LONG;
}

/// Every rank's `mine`, concatenated in rank order, on every rank. With
/// `offsets`, rank r's values are all[(*offsets)[r] .. (*offsets)[r+1]).
template <class T>
std::vector<T> allgather(MPI_Comm comm, const std::vector<T>& mine, std::vector<int>* offsets = nullptr) {
  int nprocs = 1;
  MPI_Comm_size(comm, &nprocs);
  const int count = static_cast<int>(mine.size());
  std::vector<int> counts(nprocs), displs(nprocs + 1, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 0; r < nprocs; ++r)
    displs[r + 1] = displs[r] + counts[r];
  std::vector<T> all(static_cast<std::size_t>(displs[nprocs]));
  MPI_Allgatherv(mine.data(), count, mpi_type<T>(), all.data(), counts.data(), displs.data(), mpi_type<T>(),
                 comm);
  if (offsets) *offsets = std::move(displs);
  return all;
}

/// The same on rank 0 only (empty on the other ranks).
template <class T>
std::vector<T> gather_to_root(MPI_Comm comm, const std::vector<T>& mine) {
  int nprocs = 1, rank = 0;
  MPI_Comm_size(comm, &nprocs);
  MPI_Comm_rank(comm, &rank);
  const int count = static_cast<int>(mine.size());
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::vector<T> all;
  if (rank == 0) {
    for (int r = 1; r < nprocs; ++r)
      displs[r] = displs[r - 1] + counts[r - 1];
    all.resize(static_cast<std::size_t>(displs.back()) + counts.back());
  }
  MPI_Gatherv(mine.data(), count, mpi_type<T>(), all.data(), counts.data(), displs.data(), mpi_type<T>(), 0,
              comm);
  return all;
}

/// Rank 0's string `s` on every rank (in pieces of at most 1 GiB).
inline void bcast_string(MPI_Comm comm, std::string& s) {
  std::uint64_t n = s.size();
  MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm);
  s.resize(n);
  const std::uint64_t chunk = 1u << 30;
  for (std::uint64_t off = 0; off < n; off += chunk)
    MPI_Bcast(&s[off], static_cast<int>(std::min(chunk, n - off)), MPI_CHAR, 0, comm);
}

}  // namespace granary
