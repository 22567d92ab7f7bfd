// The ImGui panels (the thesis GUI): stats with per-stage timings, open, playback and A/B, camera,
// physics, grass scale, visuals, level of detail, meadow, terrain, bodies, recording, and the
// error window. Panels never write into a running world: simulation edits build a new Session
// from the edited scenario text (App::applyScenario), one-shot body actions become recorded inputs.
#include <imgui.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>

#include "replay/physics_devices.h"
#include "viewer/app/app.h"
#include "viewer/app/keys.h"
#include "viewer/app/text.h"

namespace sg::viewer {

int App::abViewWidth(int fbw) const {
  // Side by side, the two views share what the panel column leaves (the whole width when the
  // panels are hidden): panels never cover either view.
  const int column = uiHidden_ ? 0 : std::min(360, fbw / 3);
  return std::max(1, (fbw - column) / 2);
}

void App::drawPanels() {
  const bool abSide = play_ && play_->hasB() && abView_ == AbView::Side;
  if (abSide) {  // docked in the column right of the two views
    const ImVec2 size = ImGui::GetIO().DisplaySize;
    const float x = float(2 * abViewWidth(int(size.x)));
    ImGui::SetNextWindowPos(ImVec2(x, 0), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(std::max(1.0f, size.x - x), size.y), ImGuiCond_Always);
  } else {
    ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
  }
  ImGui::Begin("SimGrass", nullptr, abSide ? ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize : 0);
  ImGui::TextDisabled("F1 help, F2 hide panels");
  panelStats();
  panelTiming();
  panelOpen();
  panelScenes();
  if (play_) {
    panelPlayback();
    if (play_->hasB()) panelAb();
  } else {
    panelLive();
  }
  panelCamera();
  panelVisuals();
  if (!play_) {
    panelPhysics();
    panelLod();
    panelMeadow();
    panelTerrain();
    panelBodies();
    panelRecording();
  }
  if (!status_.empty()) ImGui::TextWrapped("%s", status_.c_str());
  ImGui::End();
  errorWindow();
}

void App::panelStats() {
  if (!ImGui::CollapsingHeader("Stats", ImGuiTreeNodeFlags_DefaultOpen)) return;
  ImGui::Text("%s, tick %" PRId64 " (%.2f s)", scenario().name.c_str(), world().tick(),
              double(world().tick()) * scenario().timeStep.toDouble());
  ImGui::Text("frame %.1f ms, render %.1f ms (%zu tufts)", frameMs_, renderMs_, scene_.tufts.size());
  if (!play_) {
    ImGui::Text("simulation %.2f ms/tick", simMsPerTick_);
    for (size_t st = 0; st < size_t(Stage::Count); ++st)
      if (stageIsTimed(Stage(st))) ImGui::Text("  %-22s %.3f ms", timedStageName(Stage(st)), stageMs_[st]);
  }
  // On the resident GPU path a hash copies the state back: on request, not every frame.
  if (world().physicsPath() != PhysicsPath::Gpu) {
    ImGui::Text("hash %s", hex(world().stateHash()).c_str());
  } else if (hashedWorld_ == &world() && hashedTick_ == world().tick()) {
    ImGui::Text("hash %s", hex(hashedValue_).c_str());
  } else if (ImGui::Button("Hash (copies the state back)")) {
    hashedWorld_ = &world();
    hashedTick_ = world().tick();
    hashedValue_ = world().stateHash();
  }
}

void App::panelOpen() {
  if (!ImGui::CollapsingHeader("Open")) return;
  ImGui::InputText("path", openPath_, sizeof openPath_);
  if (ImGui::Button("Open")) openFile(openPath_);
  ImGui::SameLine();
  ImGui::TextDisabled("scenario .json or recording .sgr");
}

void App::panelPlayback() {
  if (!ImGui::CollapsingHeader("Playback", ImGuiTreeNodeFlags_DefaultOpen)) return;
  std::string error;
  ImGui::Text("%s", play_->recording().file.c_str());
  ImGui::TextDisabled("physics: %s", describePhysics(world()).c_str());
  ImGui::Text("tick %" PRId64 " / %" PRId64, play_->tick(), play_->lastTick());
  if (play_->busy()) {
    ImGui::Text("seeking to tick %" PRId64 "...", play_->target());
    ImGui::SameLine();
    if (ImGui::Button("Cancel (Esc)")) play_->cancel();
  }
  if (ImGui::Button(play_->playing ? "Pause (Space)" : "Play (Space)")) play_->playing = !play_->playing;
  ImGui::SameLine();
  if (ImGui::Button("Step (.)")) {
    play_->playing = false;
    if (!play_->step(1, &error)) showError(error);
  }
  ImGui::SameLine();
  if (ImGui::Button("Restart (Home)") && !play_->seek(0, &error)) showError(error);
  // The timeline seeks when the slider is let go (a seek may replay up to a snapshot interval).
  int64_t t = scrubbing_ ? scrubTick_ : play_->tick();
  const int64_t lo = play_->recording().header.startTick, hi = play_->lastTick();
  ImGui::SliderScalar("timeline", ImGuiDataType_S64, &t, &lo, &hi);
  scrubbing_ = ImGui::IsItemActive();
  scrubTick_ = t;
  if (ImGui::IsItemDeactivatedAfterEdit() && !play_->seek(t, &error)) showError(error);
  static const float speeds[] = {0.25f, 0.5f, 1, 2, 4, 8};
  static const char* names[] = {"0.25x", "0.5x", "1x", "2x", "4x", "8x"};
  int current = 2;
  for (int i = 0; i < 6; ++i)
    if (double(speeds[i]) == play_->speed) current = i;
  if (ImGui::Combo("speed", &current, names, 6)) play_->speed = speeds[current];
  if (!play_->hashesComparable()) {
    ImGui::TextDisabled("hashes: not comparable (other settings)");
  } else if (play_->firstMismatchTick() >= 0) {
    ImGui::TextColored(ImVec4(1, 0.25f, 0.25f, 1), "hash MISMATCH at tick %" PRId64, play_->firstMismatchTick());
    ImGui::TextColored(ImVec4(1, 0.25f, 0.25f, 1), "%" PRId64 " hashes checked OK", play_->hashesOk());
  } else {
    ImGui::TextColored(ImVec4(0.4f, 1, 0.4f, 1), "%" PRId64 " of %" PRId64 " hashed ticks checked OK",
                       play_->hashesOk(), play_->recording().hashedTicks());
  }
}

void App::panelAb() {
  if (!ImGui::CollapsingHeader("A/B", ImGuiTreeNodeFlags_DefaultOpen)) return;
  ImGui::TextWrapped("B: %s", play_->labelB().c_str());
  int view = abView_ == AbView::Side ? 0 : 1;
  ImGui::RadioButton("side by side", &view, 0);
  ImGui::SameLine();
  ImGui::RadioButton("divergence overlay (V)", &view, 1);
  abView_ = view == 0 ? AbView::Side : AbView::Overlay;
  if (abView_ == AbView::Overlay)
    ImGui::SliderFloat("full scale m", &heatFullScale_, 0.001f, 1.0f, "%.3f", ImGuiSliderFlags_Logarithmic);
  if (play_->measured()) {
    const TickDivergence& d = play_->divergence();
    ImGui::Text("tick %" PRId64 ": tip max %.3g m, RMS %.3g m", d.tick, d.tipMax, d.tipRms);
    ImGui::Text("bodies: %.3g m, %.3g rad%s", d.bodyPosMax, d.bodyAngleMax, d.identical ? " (identical state)" : "");
  } else {
    ImGui::TextDisabled("B is between steps (coarser time step)");
  }
  // The whole run's first divergent tick, as `simgrass diff`/`compare` find it (a scan of every
  // common tick from the start, whatever has been seeked: Playback::scanDivergence).
  if (play_->scanDone() && play_->firstDivergentTick() >= 0)
    ImGui::Text("first divergent tick: %" PRId64 " (by %s)", play_->firstDivergentTick(), play_->divergenceBy());
  else if (play_->scanDone())
    ImGui::Text("identical (by %s)", play_->divergenceBy());
  else
    ImGui::Text("first divergent tick: scanning, none up to tick %" PRId64, play_->scannedTo());
}

void App::panelLive() {
  if (!ImGui::CollapsingHeader("Live", ImGuiTreeNodeFlags_DefaultOpen)) return;
  ImGui::Text("tick %" PRId64 " of %" PRId64 " in the history%s", live_->world->tick(), live_->historyEnd(),
              paused_ ? ", paused" : "");
  if (ImGui::Button(paused_ ? "Resume (Space)" : "Pause (Space)")) handleKeyPress(GLFW_KEY_SPACE, 0);
  ImGui::SameLine();
  if (ImGui::Button("Back (,)")) stepLiveBack(1);
  ImGui::SameLine();
  if (ImGui::Button("Step (.)")) stepLive(1);
  ImGui::SameLine();
  if (ImGui::Button("Restart (Home)")) restartLive();
  // Scrubbing moves through the session's own history (kept states every snapshotEvery ticks and
  // the inputs); resuming, or any new input, continues from the tick shown.
  int64_t t = scrubbing_ ? scrubTick_ : live_->world->tick();
  const int64_t lo = 0, hi = std::max<int64_t>(1, live_->historyEnd());
  ImGui::SliderScalar("history", ImGuiDataType_S64, &t, &lo, &hi);
  scrubbing_ = ImGui::IsItemActive();
  scrubTick_ = t;
  if (ImGui::IsItemDeactivatedAfterEdit()) {
    paused_ = true;
    stepLiveBack(live_->world->tick() - std::min(t, live_->historyEnd()));
  }
  ImGui::TextDisabled("states kept every %" PRId64 " ticks (%zu)", live_->snapshotEvery(), live_->snapshotCount());
  if (ImGui::Checkbox("grass follows camera (F3)", &grassFollows_) && !grassFollows_)
    frozenCamera_ = {toRaw(cam_.camera.x), toRaw(cam_.camera.y), toRaw(cam_.camera.z)};
}

void App::panelScenes() {
  if (!ImGui::CollapsingHeader("Scenes")) return;
  ImGui::TextDisabled("Page Down / Page Up: next / previous");
  for (const std::string& f : sceneList())
    if (ImGui::Selectable(f.c_str(), !play_ && f == live_->scenario.sourceName)) openFile(f);
  if (!settings_.recent.empty()) {
    ImGui::Separator();
    ImGui::TextDisabled("recent");
    const std::vector<std::string> recent = settings_.recent;  // openFile changes the list
    for (size_t k = 0; k < recent.size(); ++k) {
      ImGui::PushID(int(k));
      const bool open = ImGui::Selectable(recent[k].c_str(), false);
      ImGui::PopID();
      if (open) openFile(recent[k]);
    }
  }
}

void App::panelTiming() {
  if (!ImGui::CollapsingHeader("Timing", ImGuiTreeNodeFlags_DefaultOpen)) return;
  // The last kTimingFrames frames as stacked bars: each timed stage of the frame's ticks, then the
  // render, in ms (the graph's top is the largest frame's total, at least 1 ms).
  static constexpr ImU32 kColours[] = {IM_COL32(120, 120, 120, 255), IM_COL32(160, 160, 60, 255),
                                       IM_COL32(80, 160, 230, 255),  IM_COL32(230, 120, 40, 255),
                                       IM_COL32(230, 60, 60, 255),   IM_COL32(60, 200, 90, 255),
                                       IM_COL32(0, 0, 0, 0),         IM_COL32(180, 90, 220, 255)};
  const ImU32 renderColour = IM_COL32(90, 90, 200, 255);
  float top = 1;
  for (const FrameTiming& f : timing_) {
    float sum = f.renderMs;
    for (float v : f.stageMs) sum += v;
    top = std::max(top, sum);
  }
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float width = std::max(50.0f, ImGui::GetContentRegionAvail().x), height = 70;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(origin, ImVec2(origin.x + width, origin.y + height), IM_COL32(20, 20, 20, 255));
  const float bar = width / float(kTimingFrames);
  for (size_t k = 0; k < kTimingFrames; ++k) {
    const FrameTiming& f = timing_[(timingNext_ + k) % kTimingFrames];  // oldest on the left
    float y = origin.y + height;
    const float x = origin.x + float(k) * bar;
    auto stack = [&](float ms, ImU32 colour) {
      const float h = ms / top * height;
      dl->AddRectFilled(ImVec2(x, y - h), ImVec2(x + std::max(1.0f, bar), y), colour);
      y -= h;
    };
    for (size_t st = 0; st < size_t(Stage::Count); ++st)
      if (stageIsTimed(Stage(st))) stack(f.stageMs[st], kColours[st]);
    stack(f.renderMs, renderColour);
  }
  ImGui::Dummy(ImVec2(width, height));
  ImGui::Text("top %.2f ms", top);
  for (size_t st = 0; st < size_t(Stage::Count); ++st) {
    if (!stageIsTimed(Stage(st))) continue;
    ImGui::ColorButton(timedStageName(Stage(st)), ImGui::ColorConvertU32ToFloat4(kColours[st]),
                       ImGuiColorEditFlags_NoTooltip, ImVec2(10, 10));
    ImGui::SameLine();
    ImGui::Text("%s", timedStageName(Stage(st)));
  }
  ImGui::ColorButton("render", ImGui::ColorConvertU32ToFloat4(renderColour), ImGuiColorEditFlags_NoTooltip,
                     ImVec2(10, 10));
  ImGui::SameLine();
  ImGui::Text("render");
}

void App::drawAbLabels(int fbw, int fbh) {
  // Window coordinates (ImGui's) may differ from framebuffer pixels on scaled displays.
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  const float scale = display.x / float(std::max(1, fbw));
  const float w = float(abViewWidth(fbw)) * scale;
  ImDrawList* dl = ImGui::GetForegroundDrawList();
  dl->AddLine(ImVec2(w, 0), ImVec2(w, float(fbh) * scale), IM_COL32(255, 255, 255, 230), 3.0f);
  auto label = [&](float x, const std::string& text) {  // clipped to its own view
    const ImVec2 size = ImGui::CalcTextSize(text.c_str());
    dl->PushClipRect(ImVec2(x, 0), ImVec2(x + w - 4, 40), true);
    dl->AddRectFilled(ImVec2(x + 6, 6), ImVec2(x + 14 + size.x, 12 + size.y), IM_COL32(0, 0, 0, 170));
    dl->AddText(ImVec2(x + 10, 9), IM_COL32(255, 255, 255, 255), text.c_str());
    dl->PopClipRect();
  };
  label(0, "A  " + std::filesystem::path(play_->recording().file).filename().string());
  std::string b = "B  " + play_->labelB();
  if (play_->measured()) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "   tip max %.3g m", play_->divergence().tipMax);
    b += buf;
  }
  label(w, b);
}

void App::drawHelp() {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(display.x * 0.5f, display.y * 0.5f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowBgAlpha(0.9f);
  bool open = true;
  ImGui::Begin("Keys (F1 or ? closes)", &open, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse);
  if (ImGui::BeginTable("keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
    for (const KeyHelp& k : kKeyHelp) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(k.keys);
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(k.what);
    }
    ImGui::EndTable();
  }
  ImGui::End();
  if (!open) helpShown_ = false;
}

void App::panelCamera() {
  if (!ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) return;
  Camera& c = cam_.camera;
  ImGui::Text("position %.2f %.2f %.2f m", c.x, c.y, c.z);
  ImGui::Text("yaw %.1f, pitch %.1f degrees", c.yawDegrees, c.pitchDegrees);
  ImGui::Checkbox("free camera (C)", &cam_.free);
  ImGui::SliderFloat("speed m/s", &cam_.tune.walkSpeed, 0.5f, 40.0f);
  if (!cam_.free) ImGui::SliderFloat("eye height", &cam_.eyeHeight, cam_.tune.minEyeHeight, 50.0f);
  if (play_) ImGui::TextDisabled("the recorded camera drives the level of detail");
}

void App::panelPhysics() {
  if (ImGui::CollapsingHeader("Physics")) {
    // Where the grass stages run (docs/gpu-physics.md): switching keeps the state bit for bit.
    static constexpr const char* kPaths[] = {"cpu", "gpu", "gpu-readback"};
    int path = int(live_->physics);
    if (ImGui::Combo("runs on", &path, kPaths, 3) && path != int(live_->physics)) {
      if (const std::string why = live_->setPhysics(PhysicsPath(path)); !why.empty())
        showError(std::string("physics ") + kPaths[path] + ": " + why);
      else
        status_ = std::string("grass stages on ") + kPaths[path] + " from tick " + std::to_string(world().tick());
    }
    ImGui::TextWrapped("%s", describePhysics(world()).c_str());
    if (world().physicsPath() != PhysicsPath::Cpu) {
      const DeviceTraffic t = world().deviceTraffic();
      ImGui::Text("copied back %.2f MB, up %.2f MB", double(t.toHost) / 1e6, double(t.toDevice) / 1e6);
      ImGui::TextDisabled(world().devicePatchDrawBuffer() ? "tufts drawn from the device's buffer"
                                                          : "tufts drawn from the host's patches");
    }
    ImGui::SliderFloat("gust strength x", &edits_.gustScale, 0.0f, 4.0f);
    ImGui::SliderFloat("gust period x", &edits_.gustPeriodScale, 0.25f, 4.0f);
    // The grass model: switching takes the new model's damping and acceleration (as the
    // `model=` variant does); the blade has its own sway frequency, damping ratio and trampling.
    static constexpr const char* kModels[] = {"thesis", "pbd", "blade"};
    const int before = edits_.model;
    if (ImGui::Combo("grass model", &edits_.model, kModels, 3) && (before == 2) != (edits_.model == 2)) {
      edits_.damping = edits_.model == 2 ? 1.0f : 0.97f;
      edits_.upAcceleration = edits_.model == 2 ? -9.81f : 1.0f;
    }
    ImGui::SliderFloat("damping /s", &edits_.damping, 0.5f, 1.0f, "%.3f");
    if (edits_.model == 2) {
      ImGui::SliderFloat("sway frequency Hz", &edits_.bladeFrequency, 0.05f, 5.0f);
      ImGui::SliderFloat("damping ratio", &edits_.bladeDampingRatio, 0.0f, 2.0f);
      ImGui::SliderFloat("trample s", &edits_.trampleSeconds, 0.0f, 60.0f);
      ImGui::SliderFloat("acceleration y m/s2", &edits_.upAcceleration, -20.0f, 5.0f);
    } else {
      ImGui::SliderFloat("stiffness (up m/s2)", &edits_.upAcceleration, 0.0f, 5.0f);
    }
    ImGui::SliderFloat("rod length m", &edits_.constraintLength, 0.2f, 3.0f);
    ImGui::SliderFloat("gravity y m/s2", &edits_.gravityY, -30.0f, 0.0f);
    if (ImGui::Button("Apply physics")) applyScenario(editedScenarioText(), false, "physics applied");
  }
  if (ImGui::CollapsingHeader("Grass scale")) {
    ImGui::SliderFloat("tuft height m", &edits_.scaleY, 0.1f, 3.0f);
    ImGui::SliderFloat("tuft half width m", &edits_.scaleXZ, 0.05f, 2.0f);
    if (ImGui::Button("Apply scale")) applyScenario(editedScenarioText(), false, "grass scale applied");
  }
  ImGui::TextDisabled("(applying builds a new world from tick 0)");
}

void App::panelVisuals() {
  if (!ImGui::CollapsingHeader("Visuals")) return;
  if (samples_ > 0) {
    ImGui::Checkbox("alpha to coverage (else alpha test)", &render_.alphaToCoverage);
  } else {
    ImGui::TextDisabled("alpha test (no MSAA: --msaa 2|4|8)");
  }
  ImGui::Checkbox("SSAO", &render_.ssao);
  ImGui::Checkbox("rock blend", &render_.rockBlend);
  ImGui::Checkbox("interpolate between ticks", &interpolate_);
  ImGui::Text("debug overlay:");
  ImGui::Checkbox("particles", &render_.debug.particles);
  ImGui::SameLine();
  ImGui::Checkbox("constraints", &render_.debug.constraints);
  ImGui::Checkbox("primitives", &render_.debug.primitives);
  ImGui::SameLine();
  ImGui::Checkbox("cells", &render_.debug.cells);
  ImGui::SameLine();
  ImGui::Checkbox("contacts", &render_.debug.contacts);
}

void App::panelLod() {
  if (!ImGui::CollapsingHeader("Level of detail")) return;
  const WorldCounts counts = world().counts();
  if (counts.lodWindow)
    ImGui::Text("on: window %" PRId64 " x %" PRId64 " patches of %" PRId64 " x %" PRId64, counts.windowPatchesX,
                counts.windowPatchesZ, counts.patchesX, counts.patchesZ);
  else
    ImGui::Text("off: all %" PRId64 " x %" PRId64 " patches simulated", counts.patchesX, counts.patchesZ);
  bool follows = counts.lodWindow;
  if (ImGui::Checkbox("simulate a window around the camera", &follows)) {
    try {
      applyScenario(editScenarioText(live_->scenario.text, live_->scenario.sourceName, "lod.mode",
                                     follows ? "\"window\"" : "\"off\""),
                    true, follows ? "level of detail on" : "level of detail off");
    } catch (const std::exception& e) {
      showError(e.what());
    }
  }
  ImGui::TextDisabled("(rebuilds the world and replays the inputs so far)");
}

void App::panelMeadow() {
  if (!ImGui::CollapsingHeader("Meadow")) return;
  ImGui::InputInt("patches x", &edits_.patchesX);
  ImGui::InputInt("patches z", &edits_.patchesZ);
  ImGui::SliderFloat("spacing m", &edits_.spacing, 0.05f, 2.0f);
  ImGui::SliderInt("interpolation k", &edits_.interpolation, 1, 4);
  if (ImGui::Button("Regenerate")) applyScenario(editedScenarioText(), false, "meadow regenerated");
}

void App::panelTerrain() {
  if (!ImGui::CollapsingHeader("Terrain")) return;
  ImGui::InputText("heightmap PNG", edits_.heightmap, sizeof edits_.heightmap);
  ImGui::SliderFloat("cell size m", &edits_.cellSize, 0.1f, 10.0f);
  ImGui::SliderFloat("max height m", &edits_.maxHeight, 0.0f, 50.0f);
  if (ImGui::Button("Load")) applyScenario(editedScenarioText(), false, "terrain loaded");
}

void App::panelBodies() {
  if (!ImGui::CollapsingHeader("Bodies", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const int64_t bodies = world().counts().bodies;
  if (bodies == 0) {
    ImGui::Text("none");
    return;
  }
  const auto& list = live_->scenario.bodies.list;
  const std::string name = size_t(selected_) < list.size() ? list[size_t(selected_)].name : std::string("spawned");
  ImGui::Text("selected %d/%" PRId64 ": %s (Tab or click)", selected_, bodies, name.c_str());
  bool follow = following_;
  if (ImGui::Checkbox("camera follows it (L)", &follow)) handleKeyPress(GLFW_KEY_L, 0);
  ImGui::Text("mode: %s (P)", positionMode_ ? "position (Displace)" : "velocity (AddVelocity)");
  ImGui::Text("drive: T/F/G/H, up/down: U/J");
  const bool on = size_t(selected_) < mowerOn_.size() ? mowerOn_[size_t(selected_)] : true;
  if (ImGui::Button(on ? "Mower off (M)" : "Mower on (M)"))
    queueBodyCommand(on ? BodyCommandKind::MowerOff : BodyCommandKind::MowerOn);
  ImGui::SameLine();
  if (ImGui::Button("Reset (Z)")) queueBodyCommand(BodyCommandKind::Reset);
  ImGui::SameLine();
  if (ImGui::Button("Spawn (N)")) queueBodyCommand(BodyCommandKind::Spawn);
  ImGui::SameLine();
  if (ImGui::Button("Shoot (B)")) shootBody();
  ImGui::TextDisabled("left drag: pull a body (recorded DragTo)");
}

void App::panelRecording() {
  if (!ImGui::CollapsingHeader("Recording", ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (live_->recorder)
    ImGui::Text("recording to %s\n%.1f KiB (R stops)", live_->recordPath.c_str(),
                double(live_->recorder->bytesWritten()) / 1024.0);
  else
    ImGui::Text("not recording (R starts)");
}

void App::errorWindow() {
  if (errorText_.empty()) return;
  ImGui::SetNextWindowPos(ImVec2(360, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(420, 0), ImGuiCond_FirstUseEver);
  bool open = true;
  ImGui::Begin("Error", &open);
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.35f, 0.35f, 1));
  ImGui::TextWrapped("%s", errorText_.c_str());
  ImGui::PopStyleColor();
  ImGui::End();
  if (!open) errorText_.clear();
}

}  // namespace sg::viewer
