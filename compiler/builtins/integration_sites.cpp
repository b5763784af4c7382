// The integrations a program performs, one per site (see integration_sites.hpp).
#include "builtins/integration_sites.hpp"

namespace sicm {

namespace {
bool g_recording = false;
std::vector<IntegrationSite> g_sites;
} // namespace

void record_integration_sites(bool on) {
  g_recording = on;
}

bool recording_integration_sites() {
  return g_recording;
}

void record_integration_site(IntegrationSite site) {
  if (!g_recording) return;
  for (const IntegrationSite &s : g_sites)
    if (s.where == site.where) return;
  g_sites.push_back(std::move(site));
}

const std::vector<IntegrationSite> &recorded_integration_sites() {
  return g_sites;
}

} // namespace sicm
