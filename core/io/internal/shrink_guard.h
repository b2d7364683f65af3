// Reading a mapped file's page that lies past the file's end raises SIGBUS, which kills the
// process: a file that another program truncates while it is read where it lies (off-core
// sampling, an upload of a file read where it lies) would crash the reader. The ranges guarded
// here are read safely instead: a SIGBUS inside one maps zero pages over the rest of the range,
// so the read that faulted (and any after it) reads zeros, and the range is marked as cut
// short for its owner to report (MappedFile::CheckSize). A SIGBUS anywhere else goes to the
// handler installed before (or kills the process, as it would have).
#ifndef NEURALMESH_CORE_IO_INTERNAL_SHRINK_GUARD_H_
#define NEURALMESH_CORE_IO_INTERNAL_SHRINK_GUARD_H_

#include <cstddef>

namespace neuralmesh::io_internal {

// The most ranges guarded at once; a range mapped while this many are guarded is not.
inline constexpr int kMaxGuardedRanges = 256;

// Guards the mapping [begin, begin + size) (page-aligned, read-only) until ReleaseRange; the
// first call installs the SIGBUS handler. Returns the range's slot, or -1 when
// kMaxGuardedRanges ranges are guarded already.
int GuardRange(const char* begin, size_t size);
// Stops guarding `slot`'s range (before it is unmapped). -1 is ignored.
void ReleaseRange(int slot);
// Whether a read in `slot`'s range faulted past the file's end (and reads zeros since).
bool RangeCutShort(int slot);

}  // namespace neuralmesh::io_internal

#endif  // NEURALMESH_CORE_IO_INTERNAL_SHRINK_GUARD_H_
