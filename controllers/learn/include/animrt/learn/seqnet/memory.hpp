#pragma once
// Training frees and allocates the same tensors at every step. glibc hands
// blocks over 128 KiB back to the kernel at once and maps them again on the
// next allocation, so a tenth of an iteration went to page faults. A program
// that trains keeps freed memory in the process instead.

namespace animrt::seqnet {

// Raises malloc's mmap and trim thresholds (256 MiB, 1 GiB): freed blocks
// stay in the heap for the next step. Process-wide; call once at start.
void keep_freed_memory();

}  // namespace animrt::seqnet
