#pragma once
// The heap's policy for the command-line tool (called once, first thing in main).
//
// Newton's iterations free and allocate again the same large buffers: the sparse factor after each symbolic
// analysis, the Hessian's pattern and value slots after each pattern rebuild of the smooth wet energy, the neighbour
// list. With glibc's defaults, blocks above a few MiB are mapped afresh and returned to the kernel when freed, and the
// heap's top is trimmed: every reuse then pays page faults and the kernel's zeroing of each page. keep_freed_memory()
// has glibc keep freed memory for reuse (blocks up to 32 MiB from the heap, no trimming, the heap grown 256 MiB at a
// time); the process's resident size then stays at its peak until it ends. A MALLOC_TRIM_THRESHOLD_,
// MALLOC_MMAP_THRESHOLD_ or MALLOC_TOP_PAD_ set in the environment is left to glibc. Results do not change.
namespace fibernet {

void keep_freed_memory();

}  // namespace fibernet
