// The program's allocator settings (cli/CMakeLists.txt links jemalloc where it is found).
//
// jemalloc reads `malloc_conf` from the program at its first allocation:
//  - thp:always: its memory is advised as transparent huge pages (the kernel's "madvise" mode, as
//    Debian ships it, backs nothing in huge pages unless asked), so a 200 MiB source image or a
//    fit's band buffers fault in by 2 MiB instead of 4 KiB;
//  - metadata_thp:auto: its own bookkeeping likewise, once it is large;
//  - dirty_decay_ms 10 s (its default, said here): memory freed by one pass of an encode is handed
//    to the next pass, and to the next file of a batch, without a trip through the kernel.
// A user's MALLOC_CONF in the environment still overrides each of these.
#if defined(CONUS_WITH_JEMALLOC)
extern "C" {
// NOLINTNEXTLINE: the name and type are jemalloc's (a weak symbol it declares, defined here).
const char* malloc_conf = "thp:always,metadata_thp:auto,dirty_decay_ms:10000";
}
#endif
