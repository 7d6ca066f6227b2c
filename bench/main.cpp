// Runs the benchmarks and then prints each core benchmark's time as a ratio to the baseline
// measured in the same run: machines here are shared, so only ratios travel.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {

class ratio_reporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name != "median") continue;
      std::string name = r.benchmark_name();
      if (const auto cut = name.find("_median"); cut != std::string::npos) name.erase(cut);
      ns_[name] = r.GetAdjustedRealTime();
    }
  }

  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\nRatios to the baseline (core time / baseline time, same run):\n");
    for (const auto& [name, ns] : ns_) {
      const std::string base = baseline_of(name);
      const auto it = ns_.find(base);
      if (base.empty() || it == ns_.end() || it->second <= 0) continue;
      std::printf("  %-40s %8.2f ns  vs %-28s %8.2f ns  ratio %.2f\n", name.c_str(), ns,
                  base.c_str(), it->second, ns / it->second);
    }
  }

 private:
  static std::string baseline_of(const std::string& name) {
    const auto swap = [&](const char* from, const char* to) -> std::string {
      const std::string f(from);
      if (name.compare(0, f.size(), f) != 0) return {};
      std::string rest = name.substr(f.size());
      if (const auto slash = rest.find('/'); slash != std::string::npos && f.back() != '/') {
        return to + rest;
      }
      return to + (f.back() == '/' ? std::string() : rest);
    };
    if (auto b = swap("drive_step_steady/", "baseline_step_steady"); !b.empty()) return b;
    if (auto b = swap("drive_step_mixed/", "baseline_step_mixed"); !b.empty()) return b;
    if (auto b = swap("drive_cycle_axes", "baseline_cycle_axes"); !b.empty()) return b;
    if (auto b = swap("compiled_quiet/", "lookup_quiet"); !b.empty()) return b;
    if (auto b = swap("compiled_transitions/", "lookup_transitions"); !b.empty()) return b;
    if (auto b = swap("profile_transitions/", "lookup_transitions"); !b.empty()) return b;
    if (name == "compiled_axes") return "lookup_axes";
    if (name == "master_new_word") return "master_repeated_word";
    if (name == "master_step_steady") return "baseline_master_steady";
    if (name == "master_step_trace") return "baseline_master_trace";
    return {};
  }
  std::map<std::string, double> ns_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  ratio_reporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
