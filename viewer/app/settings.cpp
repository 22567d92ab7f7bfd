#include "viewer/app/settings.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <system_error>

#include "replay/input_file.h"
#include "replay/output_file.h"

namespace sg::viewer {
namespace {
constexpr uint64_t kSettingsBytes = 1 << 20;
const char* kFileName = "viewer.json";
}  // namespace

void ViewerSettings::remember(const std::string& path) {
  if (path.empty()) return;
  recent.erase(std::remove(recent.begin(), recent.end(), path), recent.end());
  recent.insert(recent.begin(), path);
  if (recent.size() > kMaxRecent) recent.resize(kMaxRecent);
}

std::string defaultConfigDir() {
  if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg && xdg[0] == '/')
    return (std::filesystem::path(xdg) / "simgrass").string();
  if (const char* home = std::getenv("HOME"); home && home[0])
    return (std::filesystem::path(home) / ".config" / "simgrass").string();
  return {};
}

ViewerSettings loadSettings(const std::string& dir, std::string* warning) {
  ViewerSettings s;
  const std::string path = (std::filesystem::path(dir) / kFileName).string();
  std::error_code ec;
  if (dir.empty() || !std::filesystem::exists(path, ec)) return s;
  std::string text, expected;
  if (!readInputFile(path, kSettingsBytes, &text, &expected)) {
    *warning = path + ": expected " + expected + " (the defaults are used)";
    return s;
  }
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) {
    *warning = path + ": expected a JSON object of viewer settings (the defaults are used)";
    return s;
  }
  // Each key: taken when it has the right type, else the default with a warning naming it.
  auto take = [&](const char* key, auto* value) {
    if (!j.contains(key)) return;
    using T = std::remove_pointer_t<decltype(value)>;
    const nlohmann::json& v = j[key];
    const bool ok = std::is_same_v<T, bool> ? v.is_boolean() : v.is_number();
    if (ok) {
      *value = v.get<T>();
    } else if (warning->empty()) {
      *warning = path + ": $." + key + ": expected a " + (std::is_same_v<T, bool> ? "boolean" : "number") +
                 " (the default is used)";
    }
  };
  take("walkSpeed", &s.walkSpeed);
  if (!(s.walkSpeed >= 0.5f && s.walkSpeed <= 40.0f)) s.walkSpeed = ViewerSettings{}.walkSpeed;
  take("freeCamera", &s.freeCamera);
  take("alphaToCoverage", &s.alphaToCoverage);
  take("ssao", &s.ssao);
  take("rockBlend", &s.rockBlend);
  take("interpolate", &s.interpolate);
  take("uiHidden", &s.uiHidden);
  take("showTiming", &s.showTiming);
  if (j.contains("recent") && j["recent"].is_array())
    for (const nlohmann::json& r : j["recent"])
      if (r.is_string() && s.recent.size() < ViewerSettings::kMaxRecent && r.get<std::string>().size() < 4096)
        s.recent.push_back(r.get<std::string>());
  return s;
}

bool saveSettings(const std::string& dir, const ViewerSettings& s, std::string* error) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    *error = dir + ": expected a settings folder that exists or can be created: " + ec.message();
    return false;
  }
  const nlohmann::json j = {
      {"walkSpeed", s.walkSpeed}, {"freeCamera", s.freeCamera}, {"alphaToCoverage", s.alphaToCoverage},
      {"ssao", s.ssao},           {"rockBlend", s.rockBlend},   {"interpolate", s.interpolate},
      {"uiHidden", s.uiHidden},   {"showTiming", s.showTiming}, {"recent", s.recent}};
  return writeFileAtomic((std::filesystem::path(dir) / kFileName).string(),
                         j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n", error);
}

}  // namespace sg::viewer
