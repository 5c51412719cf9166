// Traps floating point exceptions in the physics tests, so a NaN or an overflow stops the test
// where it arises instead of propagating into a wrong number later (glibc feenableexcept).
#define CATCH_CONFIG_EXTERNAL_INTERFACES
#include <catch2/catch.hpp>

#include <cfenv>

namespace {

class TrapFloatingPointExceptions : public Catch::TestEventListenerBase {
 public:
  using Catch::TestEventListenerBase::TestEventListenerBase;
  void testCaseStarting(const Catch::TestCaseInfo&) override {
    std::feclearexcept(FE_ALL_EXCEPT);
    feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
  }
  void testCaseEnded(const Catch::TestCaseStats&) override { fedisableexcept(FE_ALL_EXCEPT); }
};

}  // namespace

CATCH_REGISTER_LISTENER(TrapFloatingPointExceptions)
