#include "pipeline/core/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>

#include <mutex>
#include <string>

namespace px {
namespace {

std::mutex& RegistryMutex() {
  static std::mutex mutex;
  return mutex;
}

spdlog::level::level_enum& DefaultLevel() {
  static spdlog::level::level_enum level = spdlog::level::info;
  return level;
}

std::string& Pattern() {
  static std::string pattern = "%H:%M:%S.%e %^%L%$ [%n] %v";
  return pattern;
}

}  // namespace

std::shared_ptr<spdlog::logger> Logger(const std::string& module) {
  std::lock_guard<std::mutex> lock(RegistryMutex());
  if (auto existing = spdlog::get(module)) return existing;
  auto logger = spdlog::stderr_color_mt(module);
  logger->set_pattern(Pattern());
  logger->set_level(DefaultLevel());
  return logger;
}

Status SetLogLevels(std::string_view spec) {
  size_t start = 0;
  while (start <= spec.size()) {
    size_t end = spec.find(',', start);
    if (end == std::string_view::npos) end = spec.size();
    std::string_view item = spec.substr(start, end - start);
    start = end + 1;
    if (item.empty()) continue;
    std::string module;
    std::string_view level_name = item;
    if (size_t eq = item.find('='); eq != std::string_view::npos) {
      module = std::string(item.substr(0, eq));
      level_name = item.substr(eq + 1);
    }
    auto level = spdlog::level::from_str(std::string(level_name));
    if (level == spdlog::level::off && level_name != "off") {
      return InvalidArgumentError("log level '" + std::string(level_name) +
                                  "' is not one of trace, debug, info, warn, error, critical, off");
    }
    if (module.empty()) {
      {
        std::lock_guard<std::mutex> lock(RegistryMutex());
        DefaultLevel() = level;
      }
      spdlog::apply_all([level](std::shared_ptr<spdlog::logger> l) { l->set_level(level); });
    } else {
      Logger(module)->set_level(level);
    }
    if (end == spec.size()) break;
  }
  return OkStatus();
}

void SetLogProcessName(std::string_view name) {
  std::lock_guard<std::mutex> lock(RegistryMutex());
  Pattern() = name.empty() ? "%H:%M:%S.%e %^%L%$ [%n] %v" : "%H:%M:%S.%e %^%L%$ [" + std::string(name) + " %n] %v";
  spdlog::apply_all([](std::shared_ptr<spdlog::logger> l) { l->set_pattern(Pattern()); });
}

}  // namespace px
