// Unit tests of the per-site integration statistics of --stats (runtime/src/stats.c).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "sicm/runtime.h"

namespace {

std::string printed() {
  char *text = nullptr;
  size_t size = 0;
  FILE *f = open_memstream(&text, &size);
  sicm_stats_print(f);
  std::fclose(f);
  std::string s(text, size);
  std::free(text);
  return s;
}

// One process holds one record, so the cases run in order in one test.
TEST(Stats, OneLinePerSiteMethodAndTolerance) {
  const sicm_ode_stats a = {100, 5, 1300, 0}, b = {40, 1, 500, 0};
  sicm_stats_add("x.sicm:3:1", "evolve", "rk8pd", 1e-10, &a, 0.5);
  EXPECT_EQ(printed(), "") << "nothing is recorded before --stats";

  sicm_stats_enable();
  sicm_stats_add("x.sicm:3:1", "evolve", "rk8pd", 1e-10, &a, 0.5);
  sicm_stats_add("x.sicm:3:1", "evolve", "rk8pd", 1e-10, &b, 0.25);
  sicm_stats_add("x.sicm:3:1", "evolve", "bulirsch-stoer", 1e-10, &b, 0.125);
  sicm_stats_add("x.sicm:9:5", "state-advancer", "rk8pd", 1e-10, &b, 0.001);
  EXPECT_EQ(printed(),
            "integration statistics (--stats), one line per site, method and tolerance:\n"
            "x.sicm:3:1: evolve, rk8pd, tolerance 1e-10: 2 calls, 140 steps (6 rejected), 1800 rhs "
            "evaluations, .75 s\n"
            "x.sicm:3:1: evolve, bulirsch-stoer, tolerance 1e-10: 1 call, 40 steps (1 rejected), "
            "500 "
            "rhs evaluations, .125 s\n"
            "x.sicm:9:5: state-advancer, rk8pd, tolerance 1e-10: 1 call, 40 steps (1 rejected), "
            "500 "
            "rhs evaluations, .001 s\n");

  // The events a crossings call located, and what placing them cost.
  const sicm_ode_event_stats events = {12, 340, 95}, none = {0, 0, 0};
  sicm_stats_add("x.sicm:12:1", "crossings", "rk8pd", 1e-12, &a, 0.5);
  sicm_stats_add_events("x.sicm:12:1", "crossings", "rk8pd", 1e-12, &events);
  sicm_stats_add_events("x.sicm:9:5", "state-advancer", "rk8pd", 1e-10, &none);
  const std::string all = printed();
  EXPECT_NE(all.find("x.sicm:12:1: crossings, rk8pd, tolerance 1e-12: 1 call, 100 steps (5 "
                     "rejected), 1300 rhs evaluations, 12 events located (340 placement "
                     "integrations; 95 steps screened free of events), .5 s\n"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("x.sicm:9:5: state-advancer, rk8pd, tolerance 1e-10: 1 call, 40 steps (1 "
                     "rejected), 500 rhs evaluations, .001 s\n"),
            std::string::npos)
      << all;
}

} // namespace
