// The trace recorder's JSON: time stamps and durations keep their sub-microsecond digits however
// late in a run an event falls, so that events nest in a viewer and in bench/evaluation_sizes.py.
#include <gtest/gtest.h>

#include <string>

#include "parallel/trace.hpp"

using namespace sphdisk;

TEST(Trace, TimeStampsKeepTheirDigitsLateInALongRun) {
  // 123.4567891 s into a run (in microseconds), 0.5 us long; written relative to origin 1,000 us.
  par::trace_record("late_event_of_this_test", 123456789.1234, 123456789.6234);
  const std::string json = par::trace_events(0, 1000.0);
  const auto at = json.find("\"name\":\"late_event_of_this_test\"");
  ASSERT_NE(at, std::string::npos);
  const std::string event = json.substr(at, json.find('}', at) - at);
  EXPECT_NE(event.find("\"ts\":123455789.123,"), std::string::npos) << event;
  EXPECT_NE(event.find("\"dur\":0.500"), std::string::npos) << event;
}
