// Shared state between the fuzzer and its stand-in Engine.
#pragma once

namespace granary {
namespace fuzz {
/// Commands left for the current input (reset by the fuzzer for each input).
inline long command_budget = 0;
}  // namespace fuzz
}  // namespace granary
