// `sicm bench`: work-precision runs per integration site (see work_precision.hpp).
#include "bench/work_precision.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "builtins/integration_sites.hpp"
#include "builtins/numerics_defaults.hpp"
#include "sicm/runtime.h"

namespace sicm {

namespace {

// Every adaptive method sicm has (the fixed-step symplectic methods take a
// step size, not a tolerance), but qcctrap2: of order 3, it runs into the
// step limit below tolerance 1e-12 on the free rigid body, after half a
// second a run. gear and explicit-gear are msbdf.
const char *const kAdaptiveMethods[] = {"bulirsch-stoer", "rk8pd",    "rkf45",           "rkck",
                                        "qcrk4",          "taylor",   "taylor-extended", "msbdf",
                                        "cvode-adams",    "cvode-bdf"};

// Tried in order for the reference (see run_work_precision).
const char *const kReferenceMethods[] = {"bulirsch-stoer", "rk8pd", "cvode-bdf"};

// Repeat a run until it has been timed this often when it takes under a
// second (noisy machines: the median of three is the least a time can be).
constexpr int kMinRepeatsOfShortRuns = 3;

struct Run {
  std::string method;
  double tolerance = 0;
  bool ok = false;
  double seconds = 0; // median
  sicm_ode_stats work{};
  std::vector<double> final;
  double error = 0;
  std::string why_not; // when !ok: the integrator's reason (too many steps, ...)
};

int call_kernel(double, const double *y, double *dydt, void *data) {
  const IntegrationSite &site = *static_cast<const IntegrationSite *>(data);
  site.kernel(y, dydt, site.params.empty() ? nullptr : site.params.data());
  return 0;
}

void quiet(const char *, int) {}

// One integration over the site's interval in one call; the state where it
// ended (or stopped), the work and the seconds.
Run integrate_once(const IntegrationSite &site, const sicm_ode_step_type *T, double tolerance) {
  Run r;
  r.tolerance = tolerance;
  sicm_ode *o = sicm_ode_alloc(T, site.y.size(), call_kernel, const_cast<IntegrationSite *>(&site),
                               tolerance, tolerance);
  r.final = site.y;
  if (!o) {
    r.why_not = "the integrator could not be made";
    return r;
  }
  const double *p = site.params.empty() ? nullptr : site.params.data();
  if (T == sicm_ode_step_taylor && site.taylor) sicm_ode_set_taylor(o, site.taylor, p);
  if (T == sicm_ode_step_taylor_extended && site.taylor_extended)
    sicm_ode_set_taylor_extended(o, site.taylor_extended, p);
  double t = site.t0;
  const double start = sicm_stats_clock();
  r.ok = sicm_ode_evolve(o, &t, site.t1, r.final.data()) == SICM_SUCCESS;
  r.seconds = sicm_stats_clock() - start;
  if (!r.ok) r.why_not = sicm_ode_last_error(o);
  if (site.time_first) r.final[0] = t; // the integrator's time, exactly
  r.work = *sicm_ode_get_stats(o);
  sicm_ode_free(o);
  return r;
}

Run timed_run(const IntegrationSite &site, const std::string &method, double tolerance,
              int repeats) {
  const sicm_ode_step_type *T = integrator_named(method);
  std::vector<double> times;
  Run r = integrate_once(site, T, tolerance);
  r.method = method;
  if (!r.ok) return r; // nothing to time
  times.push_back(r.seconds);
  int wanted = r.seconds < 1.0 ? std::max(repeats, kMinRepeatsOfShortRuns) : repeats;
  for (int k = 1; k < wanted; ++k)
    times.push_back(integrate_once(site, T, tolerance).seconds);
  std::sort(times.begin(), times.end());
  r.seconds = times[times.size() / 2];
  r.method = method;
  return r;
}

double distance(const std::vector<double> &a, const std::vector<double> &b) {
  double d = 0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i)
    d = std::max(d, std::fabs(a[i] - b[i]));
  return d;
}

std::string round_trip(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  if (std::isnan(x)) return "nan";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

std::string short_number(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// ---- the diagram -----------------------------------------------------------------------

constexpr double kPanelWidth = 640, kPanelHeight = 420, kMargin = 60, kLegendWidth = 150;
// One color per adaptive method (nine), so no two curves share one.
const char *const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                               "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};

std::string xml_escaped(const std::string &s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

// One panel: log10 error (down: more accurate) against log10 seconds.
std::string panel(const IntegrationSite &site, const std::vector<Run> &runs, double top) {
  std::vector<const Run *> shown;
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  for (const Run &r : runs) {
    if (!r.ok || !(r.seconds > 0)) continue;
    shown.push_back(&r);
    double x = std::log10(r.seconds), y = std::log10(std::max(r.error, 1e-18));
    xmin = std::min(xmin, x), xmax = std::max(xmax, x);
    ymin = std::min(ymin, y), ymax = std::max(ymax, y);
  }
  std::string s = "<g transform=\"translate(0," + round_trip(top) + ")\">\n";
  s += "<text x=\"" + round_trip(kMargin) + "\" y=\"20\" font-size=\"14\">" +
       xml_escaped(site.where + " (" + site.who + ")") + "</text>\n";
  if (shown.empty()) return s + "<text x=\"60\" y=\"60\">no run succeeded</text>\n</g>\n";
  xmin = std::floor(xmin), xmax = std::ceil(xmax), ymin = std::floor(ymin), ymax = std::ceil(ymax);
  if (xmax == xmin) xmax += 1;
  if (ymax == ymin) ymax += 1;
  const double w = kPanelWidth - 2 * kMargin, h = kPanelHeight - 2 * kMargin;
  auto px = [&](double x) { return kMargin + (x - xmin) / (xmax - xmin) * w; };
  auto py = [&](double y) { return kMargin + (ymax - y) / (ymax - ymin) * h; };
  s += "<rect x=\"" + round_trip(kMargin) + "\" y=\"" + round_trip(kMargin) + "\" width=\"" +
       round_trip(w) + "\" height=\"" + round_trip(h) + "\" fill=\"none\" stroke=\"black\"/>\n";
  for (double d = xmin; d <= xmax; d += 1)
    s += "<line x1=\"" + round_trip(px(d)) + "\" y1=\"" + round_trip(kMargin + h) + "\" x2=\"" +
         round_trip(px(d)) + "\" y2=\"" + round_trip(kMargin + h + 5) +
         "\" stroke=\"black\"/><text x=\"" + round_trip(px(d)) + "\" y=\"" +
         round_trip(kMargin + h + 20) + "\" font-size=\"11\" text-anchor=\"middle\">1e" +
         std::to_string(static_cast<int>(d)) + "</text>\n";
  for (double d = ymin; d <= ymax; d += 1)
    s += "<line x1=\"" + round_trip(kMargin - 5) + "\" y1=\"" + round_trip(py(d)) + "\" x2=\"" +
         round_trip(kMargin) + "\" y2=\"" + round_trip(py(d)) + "\" stroke=\"black\"/><text x=\"" +
         round_trip(kMargin - 8) + "\" y=\"" + round_trip(py(d) + 4) +
         "\" font-size=\"11\" text-anchor=\"end\">1e" + std::to_string(static_cast<int>(d)) +
         "</text>\n";
  s += "<text x=\"" + round_trip(kMargin + w / 2) + "\" y=\"" + round_trip(kPanelHeight - 12) +
       "\" font-size=\"12\" text-anchor=\"middle\">seconds</text>\n";
  s += "<text x=\"14\" y=\"" + round_trip(kMargin + h / 2) +
       "\" font-size=\"12\" transform=\"rotate(-90 14 " + round_trip(kMargin + h / 2) +
       ")\" text-anchor=\"middle\">error of the final state</text>\n";
  std::vector<std::string> methods;
  for (const Run *r : shown)
    if (std::find(methods.begin(), methods.end(), r->method) == methods.end())
      methods.push_back(r->method);
  for (size_t m = 0; m < methods.size(); ++m) {
    const char *color = kColors[m % (sizeof kColors / sizeof *kColors)];
    std::string points;
    for (const Run *r : shown) {
      if (r->method != methods[m]) continue;
      double x = px(std::log10(r->seconds)), y = py(std::log10(std::max(r->error, 1e-18)));
      points += round_trip(x) + "," + round_trip(y) + " ";
      s += "<circle cx=\"" + round_trip(x) + "\" cy=\"" + round_trip(y) + "\" r=\"2.5\" fill=\"" +
           color + "\"/>\n";
    }
    s += "<polyline points=\"" + points + "\" fill=\"none\" stroke=\"" + color + "\"/>\n";
    double ly = kMargin + 16 * static_cast<double>(m);
    s += "<line x1=\"" + round_trip(kPanelWidth + 10) + "\" y1=\"" + round_trip(ly) + "\" x2=\"" +
         round_trip(kPanelWidth + 30) + "\" y2=\"" + round_trip(ly) + "\" stroke=\"" + color +
         "\"/><text x=\"" + round_trip(kPanelWidth + 36) + "\" y=\"" + round_trip(ly + 4) +
         "\" font-size=\"12\">" + xml_escaped(methods[m]) + "</text>\n";
  }
  return s + "</g>\n";
}

bool write_file(const std::string &path, const std::string &text) {
  FILE *f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  return std::fclose(f) == 0 && ok;
}

} // namespace

int run_work_precision(const BenchOptions &options) {
  std::vector<std::string> methods = options.methods;
  if (methods.empty()) methods.assign(std::begin(kAdaptiveMethods), std::end(kAdaptiveMethods));
  std::vector<double> tolerances;
  for (double t = options.tolerance_from; t >= options.tolerance_to * (1 - 1e-9); t /= 10)
    tolerances.push_back(std::stod(short_number(t))); // 1e-3, 1e-4, ... exactly as written
  mkdir(options.out_dir.c_str(), 0777);
  sicm_error_handler_t *old = sicm_set_error_handler(quiet);
  std::string tsv = "site\tmethod\ttolerance\tseconds\tsteps\trhs_evals\terror\tfinal\n";
  std::string svg_body;
  double svg_top = 0;
  const std::vector<IntegrationSite> &sites = recorded_integration_sites();
  if (sites.empty()) std::printf("the program performs no integration\n");
  for (const IntegrationSite &site : sites) {
    std::printf("%s: %s from t = %s to %s (%s at %s in the program)\n", site.where.c_str(),
                site.who.c_str(), short_number(site.t0).c_str(), short_number(site.t1).c_str(),
                site.method.c_str(), short_number(site.tolerance).c_str());
    if (!site.kernel) {
      std::printf("  not benchmarked: its system derivative could not be compiled\n");
      continue;
    }
    // The reference: the Taylor integrator in long double well under the
    // rounding of double when the derivative has Taylor coefficients (its
    // error estimated by its distance from itself at ten times the
    // tolerance); else the first of kReferenceMethods that gets through at
    // the reference tolerance (an explicit method stops on a stiff system),
    // its error estimated by its distance from the next that does.
    std::vector<Run> candidates;
    candidates.reserve(3); // `reference` below stays valid while one more is added
    if (site.taylor_extended) {
      const double tol = kExtendedReferenceTolerance;
      Run best = integrate_once(site, sicm_ode_step_taylor_extended, tol);
      Run next = integrate_once(site, sicm_ode_step_taylor_extended, 10 * tol);
      best.method = "taylor-extended at " + short_number(tol);
      next.method = "taylor-extended at " + short_number(10 * tol);
      if (best.ok && next.ok) candidates = {std::move(best), std::move(next)};
    }
    for (const char *m : kReferenceMethods) {
      if (candidates.size() == 2) break;
      Run r = integrate_once(site, integrator_named(m), kReferenceTolerance);
      r.method = m;
      if (r.ok) candidates.push_back(std::move(r));
    }
    if (candidates.empty()) {
      std::printf("  not benchmarked: no method reaches the end at tolerance %s\n",
                  short_number(kReferenceTolerance).c_str());
      continue;
    }
    const Run &reference = candidates[0];
    if (candidates.size() == 1) { // no second method: the same at ten times the tolerance
      Run looser = integrate_once(site, integrator_named(reference.method.c_str()),
                                  10 * kReferenceTolerance);
      looser.method = reference.method + " at " + short_number(10 * kReferenceTolerance);
      if (looser.ok) candidates.push_back(std::move(looser));
    }
    const double reference_error =
        candidates.size() > 1 ? distance(reference.final, candidates[1].final) : INFINITY;
    std::printf("  reference: %s%s; its estimated error %s (its distance from %s)\n",
                reference.method.c_str(),
                reference.method.find(" at ") == std::string::npos
                    ? (" at tolerance " + short_number(kReferenceTolerance)).c_str()
                    : "",
                short_number(reference_error).c_str(),
                candidates.size() > 1 ? candidates[1].method.c_str() : "nothing else");
    std::vector<Run> runs;
    for (const std::string &m : methods)
      for (double tol : tolerances) {
        Run r = timed_run(site, m, tol, options.repeats);
        // A run that failed says why. One that took no step at all (a
        // fixed-step method refusing a step too small for the step limit)
        // has no row; one that stopped on the way is a row of error inf
        // with the state where it stopped.
        if (!r.ok) {
          std::printf("  %s for %s at %s: %s\n", r.work.steps == 0 ? "no row" : "stopped",
                      m.c_str(), short_number(tol).c_str(), r.why_not.c_str());
          if (r.work.steps == 0) continue;
        }
        r.error = r.ok ? distance(r.final, reference.final) : INFINITY;
        tsv += site.where + "\t" + m + "\t" + short_number(tol) + "\t" + round_trip(r.seconds) +
               "\t" + std::to_string(r.work.steps) + "\t" + std::to_string(r.work.rhs_evals) +
               "\t" + round_trip(r.error) + "\t";
        for (size_t i = 0; i < r.final.size(); ++i)
          tsv += (i ? " " : "") + round_trip(r.final[i]);
        tsv += "\n";
        runs.push_back(std::move(r));
      }
    // The cheapest run reaching each decade of accuracy.
    std::printf("  %-10s %-16s %s\n", "error <=", "cheapest", "seconds");
    for (int d = 1; d <= 17; ++d) {
      const double bound = std::pow(10.0, -d);
      if (bound < reference_error) {
        std::printf("  (smaller errors are below the reference's own)\n");
        break;
      }
      const Run *best = nullptr;
      for (const Run &r : runs)
        if (r.ok && r.error <= bound && (!best || r.seconds < best->seconds)) best = &r;
      if (!best) break;
      std::printf("  %-10s %-16s %s\n", ("1e-" + std::to_string(d)).c_str(), best->method.c_str(),
                  short_number(best->seconds).c_str());
    }
    svg_body += panel(site, runs, svg_top);
    svg_top += kPanelHeight;
  }
  sicm_set_error_handler(old);
  std::string svg = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                    "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
                    round_trip(kPanelWidth + kLegendWidth) + "\" height=\"" +
                    round_trip(std::max(svg_top, kPanelHeight)) + "\">\n" +
                    "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n" + svg_body +
                    "</svg>\n";
  const std::string tsv_path = options.out_dir + "/work-precision.tsv";
  const std::string svg_path = options.out_dir + "/work-precision.svg";
  if (!write_file(tsv_path, tsv) || !write_file(svg_path, svg)) {
    std::fprintf(stderr, "sicm bench: cannot write %s\n", options.out_dir.c_str());
    return 1;
  }
  std::printf("wrote %s and %s\n", tsv_path.c_str(), svg_path.c_str());
  return 0;
}

} // namespace sicm
