#pragma once
// This process's resident memory, for the run summary: the peak, and the heap and stacks apart
// from mapped files (a replay maps its recording; those pages are the file's, not posed's).

namespace posed {

/// From /proc/self/status [MB]; negative where unreadable.
struct ResidentMemory {
  double peak_mb = -1;  ///< VmHWM: the largest resident set so far, mapped files included
  double anon_mb = -1;  ///< RssAnon: heap and stacks now
};
ResidentMemory read_resident_memory();

}  // namespace posed
