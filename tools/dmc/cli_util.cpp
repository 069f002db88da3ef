#include "cli_util.h"

#include <unistd.h>

#include <cstdio>
#include <iostream>

namespace dmc::cli {

int ReportError(std::string_view command, const Status& status, bool json) {
  if (json) {
    nlohmann::json error = {{"error",
                             {{"code", static_cast<int>(status.code())},
                              {"name", std::string(ErrorCodeName(status.code()))},
                              {"message", status.message()}}}};
    std::cout << error.dump(2) << std::endl;
  }
  std::cerr << "dmc " << command << ": error: " << status.ToString() << std::endl;
  return ExitCodeFor(status.code());
}

void ReportWarning(std::string_view command, std::string_view text) {
  std::cerr << "dmc " << command << ": warning: " << text << std::endl;
}

void PrintJson(const nlohmann::json& document) { std::cout << document.dump(2) << std::endl; }

Progress::Progress(std::string label, long total)
    : label_(std::move(label)), total_(total), enabled_(isatty(STDERR_FILENO) != 0) {}

void Progress::Update(long done) {
  if (!enabled_ || total_ <= 0) return;
  const int percent = static_cast<int>(100 * done / total_);
  if (percent == last_percent_) return;
  last_percent_ = percent;
  std::fprintf(stderr, "\r%s %3d%%", label_.c_str(), percent);
  std::fflush(stderr);
}

Progress::~Progress() {
  if (enabled_ && last_percent_ >= 0) std::fprintf(stderr, "\n");
}

}  // namespace dmc::cli
