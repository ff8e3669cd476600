// Which copy of the planned pyramid decode runs (decode_planned.cpp): the baseline x86-64 one (SSE2), or
// one compiled for x86-64-v3 (AVX2) where the processor has it. Both give the same floats; the
// switch lets the tests compare them on one machine.
#pragma once

namespace conus::codec::detail {

// Whether this build and this processor have the AVX2 copy.
bool decodeAvx2Available();
// Forces the baseline copy (true) or goes back to the processor's choice (false). For tests:
// not thread-safe against decodes running at the same time.
void forceBaselineDecode(bool baseline);

}  // namespace conus::codec::detail
