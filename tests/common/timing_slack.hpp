// The factor by which a test's wall-clock bound grows under AddressSanitizer and UBSan, whose
// instrumented code runs 3-10x slower on a loaded machine. A bound checks that a budget is
// enforced promptly (the solve stops within a small multiple of its budget, not at its natural
// end seconds later); what is checked does not change, only the margin for the machine.
#pragma once

namespace mlcp::test {

#if defined(__SANITIZE_ADDRESS__)
constexpr double kTimingSlack = 8.0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr double kTimingSlack = 8.0;
#else
constexpr double kTimingSlack = 1.0;
#endif
#else
constexpr double kTimingSlack = 1.0;
#endif

}  // namespace mlcp::test
