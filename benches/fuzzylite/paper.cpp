// Times fuzzylite 6 (Debian's libfuzzylite-dev) on the paper's controller, read from the same
// `.fis` file hrm ships (crates/fuzzy-sugeno/data/paper.fis: 4 inputs, 8 bell sets, 16 rules,
// 2 outputs), at the input of hrm's `fuzzy/paper` bench (benches/benches/fuzzy.rs). Prints the
// median over batches of the time per evaluation, `fuzzylite/paper <ns> ns` (the figure
// `cargo xtask bench --check` reads), and the two outputs, which must
// equal hrm's at the same input (a check that both evaluate the same system).
//
// Build and run with ./run.sh.

#include <fl/Headers.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s paper.fis\n", argv[0]);
    return 2;
  }
  std::unique_ptr<fl::Engine> engine(fl::FisImporter().fromFile(argv[1]));
  std::string status;
  if (!engine->isReady(&status)) {
    std::fprintf(stderr, "fuzzylite: the engine is not ready: %s\n", status.c_str());
    return 1;
  }
  const double x[4] = {0.12, -0.07, 0.4, -0.25};
  auto evaluate = [&] {
    for (int i = 0; i < 4; ++i) engine->getInputVariable(i)->setValue(x[i]);
    engine->process();
  };
  const int calls = 20000, batches = 51;
  std::vector<double> times;
  for (int b = 0; b < batches; ++b) {
    auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < calls; ++i) evaluate();
    auto stop = std::chrono::steady_clock::now();
    times.push_back(std::chrono::duration<double, std::nano>(stop - start).count() / calls);
  }
  std::sort(times.begin(), times.end());
  std::printf("fuzzylite/paper %.1f ns\n", times[times.size() / 2]);
  std::printf("  check: outputs %.15g %.15g\n", engine->getOutputVariable(0)->getValue(),
              engine->getOutputVariable(1)->getValue());
  return 0;
}
