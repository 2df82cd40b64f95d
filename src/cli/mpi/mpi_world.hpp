// The MPI job as rtcl uses it: one MPI_COMM_WORLD with MPI_ERRORS_RETURN
// (an MPI failure is an Error naming the call, not an abort), byte messages
// and broadcasts. Waits poll with short sleeps instead of blocking in MPI,
// whose progress loop would otherwise spin a core that the renderer of the
// same host needs.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace rtcl::cli {

class MpiWorld {
 public:
  // MPI_Init_thread with MPI_THREAD_FUNNELED (only the calling thread uses
  // MPI; rank 0 renders in a second thread). Throws Error when MPI cannot
  // start or offers less.
  MpiWorld();
  ~MpiWorld();  // MPI_Finalize
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;

  int rank = 0, size = 1;
  // Rank and size among the ranks of this host (MPI_COMM_TYPE_SHARED): the
  // local rank picks the OpenCL device.
  int local_rank = 0, local_size = 1;
  std::string host;  // MPI_Get_processor_name
};

// Throws Error "MPI: <call>: <MPI's error string>" unless rc is MPI_SUCCESS.
void check_mpi(int rc, const char* call);

struct Message {
  int source = -1, tag = -1;
  std::vector<std::byte> bytes;
};

void send_bytes(int dest, int tag, std::span<const std::byte> bytes);
// The next message from `source` (any tag; -1: from any rank), if one has
// arrived.
std::optional<Message> poll_message(int source = -1);
// Waits for the next message from `source`.
Message wait_message(int source);

// MPI_Bcast of a byte string of any size from `root` (sent as its length,
// then in chunks of at most 1 GiB): `bytes` is read on the root and
// replaced elsewhere.
void broadcast_bytes(std::vector<std::byte>& bytes, int root);

// Text in and out of byte messages.
std::vector<std::byte> as_bytes(const std::string& text);
std::string as_text(std::span<const std::byte> bytes);

}  // namespace rtcl::cli
