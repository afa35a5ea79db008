// StrtodC when newlocale fails (gaps14): the C locale it reads numbers in is
// made once, by newlocale, which can fail (ENOMEM). Before, a failure left a
// null locale_t, given to strtod_l on every call after (undefined behaviour);
// now that call throws an Error naming newlocale and its reason, and the next
// one tries again. This executable is linked with -Wl,--wrap=newlocale
// (tests/core/CMakeLists.txt): __wrap_newlocale fails while told to.
#include "robotalk/error.h"
#include "robotalk/sequence_file.h"

#include <gtest/gtest.h>

#include <locale.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>

namespace {
std::atomic<int> fail_newlocale{0};
std::atomic<int> newlocale_calls{0};
}  // namespace

extern "C" locale_t __real_newlocale(int mask, const char* locale, locale_t base);
extern "C" locale_t __wrap_newlocale(int mask, const char* locale, locale_t base) {
  ++newlocale_calls;
  if (fail_newlocale > 0) {
    --fail_newlocale;
    errno = ENOMEM;
    return static_cast<locale_t>(nullptr);
  }
  return __real_newlocale(mask, locale, base);
}

namespace robotalk {
namespace {

TEST(StrtodC, ANewlocaleFailureIsAnErrorNamingItAndTheNextCallTriesAgain) {
  fail_newlocale = 1;
  try {
    NumberOf("0.25");
    if (newlocale_calls == 0) GTEST_SKIP() << "newlocale is not wrapped here (a shared robotalk-core)";
    ADD_FAILURE() << "a number was read without the C locale";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("newlocale"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::strerror(ENOMEM)), std::string::npos) << e.what();
  }
  EXPECT_EQ(NumberOf("0.25"), 0.25) << "made on the next call";
  const int calls = newlocale_calls;
  EXPECT_EQ(NumberOf("-1.5e3"), -1500.0);
  EXPECT_EQ(newlocale_calls, calls) << "made once, then kept";
}

}  // namespace
}  // namespace robotalk
