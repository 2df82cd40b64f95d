#include "mpi/mpi_world.hpp"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <thread>

#include "rtcl/error.hpp"

namespace rtcl::cli {

namespace {

// Between two polls of a wait: short against a tile (milliseconds), long
// enough that a waiting rank costs no measurable CPU.
constexpr std::chrono::microseconds poll_interval{100};

void wait_for(MPI_Request& request, const char* call) {
  for (;;) {
    int done = 0;
    check_mpi(MPI_Test(&request, &done, MPI_STATUS_IGNORE), call);
    if (done) return;
    std::this_thread::sleep_for(poll_interval);
  }
}

}  // namespace

void check_mpi(int rc, const char* call) {
  if (rc == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  if (MPI_Error_string(rc, text, &length) != MPI_SUCCESS) length = 0;
  throw Error(std::string("MPI: ") + call + ": " + (length > 0 ? std::string(text, length) : "error " + std::to_string(rc)));
}

MpiWorld::MpiWorld() {
  int provided = 0;
  check_mpi(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  check_mpi(MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
  if (provided < MPI_THREAD_FUNNELED) throw Error("MPI: the library offers no MPI_THREAD_FUNNELED support");
  check_mpi(MPI_Comm_rank(MPI_COMM_WORLD, &rank), "MPI_Comm_rank");
  check_mpi(MPI_Comm_size(MPI_COMM_WORLD, &size), "MPI_Comm_size");
  MPI_Comm local;
  check_mpi(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &local),
            "MPI_Comm_split_type");
  check_mpi(MPI_Comm_rank(local, &local_rank), "MPI_Comm_rank");
  check_mpi(MPI_Comm_size(local, &local_size), "MPI_Comm_size");
  MPI_Comm_free(&local);
  char name[MPI_MAX_PROCESSOR_NAME];
  int length = 0;
  check_mpi(MPI_Get_processor_name(name, &length), "MPI_Get_processor_name");
  host.assign(name, length);
}

MpiWorld::~MpiWorld() { MPI_Finalize(); }

void send_bytes(int dest, int tag, std::span<const std::byte> bytes) {
  if (bytes.size() > std::size_t(std::numeric_limits<int>::max()))
    throw Error("MPI: a message of " + std::to_string(bytes.size()) + " bytes is more than one send carries");
  MPI_Request request;
  check_mpi(MPI_Isend(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, dest, tag, MPI_COMM_WORLD, &request),
            "MPI_Isend");
  wait_for(request, "MPI_Isend");
}

std::optional<Message> poll_message(int source) {
  int flag = 0;
  MPI_Status status;
  check_mpi(MPI_Iprobe(source < 0 ? MPI_ANY_SOURCE : source, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status),
            "MPI_Iprobe");
  if (!flag) return std::nullopt;
  int count = 0;
  check_mpi(MPI_Get_count(&status, MPI_BYTE, &count), "MPI_Get_count");
  Message m;
  m.source = status.MPI_SOURCE;
  m.tag = status.MPI_TAG;
  m.bytes.resize(static_cast<std::size_t>(count));
  check_mpi(MPI_Recv(m.bytes.data(), count, MPI_BYTE, m.source, m.tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
            "MPI_Recv");
  return m;
}

Message wait_message(int source) {
  for (;;) {
    if (std::optional<Message> m = poll_message(source)) return std::move(*m);
    std::this_thread::sleep_for(poll_interval);
  }
}

void broadcast_bytes(std::vector<std::byte>& bytes, int root) {
  int rank = 0;
  check_mpi(MPI_Comm_rank(MPI_COMM_WORLD, &rank), "MPI_Comm_rank");
  std::uint64_t size = bytes.size();
  check_mpi(MPI_Bcast(&size, 1, MPI_UINT64_T, root, MPI_COMM_WORLD), "MPI_Bcast");
  if (rank != root) bytes.resize(static_cast<std::size_t>(size));
  constexpr std::size_t chunk = std::size_t(1) << 30;
  for (std::size_t at = 0; at < bytes.size(); at += chunk) {
    int n = static_cast<int>(std::min(chunk, bytes.size() - at));
    check_mpi(MPI_Bcast(bytes.data() + at, n, MPI_BYTE, root, MPI_COMM_WORLD), "MPI_Bcast");
  }
}

std::vector<std::byte> as_bytes(const std::string& text) {
  const auto* p = reinterpret_cast<const std::byte*>(text.data());
  return std::vector<std::byte>(p, p + text.size());
}

std::string as_text(std::span<const std::byte> bytes) {
  return std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

}  // namespace rtcl::cli
