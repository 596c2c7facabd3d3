// Tests of quoteInput (quote_input.cpp): control bytes escaped, UTF-8 kept, long text cut.
#include "vox/core/quote_input.h"

#include <gtest/gtest.h>

#include <string>

namespace vox {
namespace {

TEST(QuoteInput, OneShortLine) {
  EXPECT_EQ(quoteInput("abc"), "abc");
  EXPECT_EQ(quoteInput("a\nb\x1b[31m\x7f"), "a\\x0ab\\x1b[31m\\x7f");
  EXPECT_EQ(quoteInput("caf\xc3\xa9"), "caf\xc3\xa9");  // UTF-8 passes
  EXPECT_EQ(quoteInput(std::string(10'000'000, 'A'), 40), std::string(40, 'A') + "...");
}

}  // namespace
}  // namespace vox
