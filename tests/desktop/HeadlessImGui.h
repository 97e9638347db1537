#pragma once
// Dear ImGui without a platform or renderer backend, driven as a user would:
// a fixed display (1280x800, the desktop viewer's default window), the font
// atlas built, 60 frames a second, and the mouse and keyboard state set
// before each frame. A widget is found by its ID path (the labels and
// PushID numbers the panel gives it, from its window): ImGui's navigation
// is pointed at that ID for a frame, which records the widget's rectangle
// where the panel draws it (ImGuiWindow::NavRectRel), and the mouse then
// moves to its centre, is checked to hover that very widget, and presses.
// What the panel drew is never looked at: the tests check the models.
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <initializer_list>
#include <string>
#include <utility>

#include <imgui.h>
#include <imgui_internal.h>

namespace tessera::test {

// One step of a widget's ID path: a label ("##visible") or a PushID number.
struct IdPart {
  IdPart(const char* label) : text(label) {}    // NOLINT: paths read as {0, "##visible"}
  IdPart(int n) : isNumber(true), number(n) {}  // NOLINT
  std::string text;
  bool isNumber = false;
  int number = 0;
};

class HeadlessImGui {
 public:
  static constexpr float kWidth = 1280.0f, kHeight = 800.0f;

  // `draw` submits the widgets of one frame (between NewFrame and Render).
  explicit HeadlessImGui(std::function<void()> draw) : draw_(std::move(draw)) {
    context_ = ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;
    io.DisplaySize = ImVec2(kWidth, kHeight);
    unsigned char* pixels = nullptr;
    int w = 0, h = 0;
    io.Fonts->GetTexDataAsRGBA32(&pixels, &w, &h);  // the atlas a backend would upload
    ImGui::StyleColorsDark();
    frame();
  }
  ~HeadlessImGui() { ImGui::DestroyContext(context_); }
  HeadlessImGui(const HeadlessImGui&) = delete;
  HeadlessImGui& operator=(const HeadlessImGui&) = delete;

  // One frame with the mouse at `mouse`, the left button down or not.
  void frame(ImVec2 mouse = ImVec2(-FLT_MAX, -FLT_MAX), bool down = false, bool ctrl = false) {
    ImGuiIO& io = ImGui::GetIO();
    io.DeltaTime = 1.0f / 60.0f;
    io.MousePos = mouse;
    io.MouseDown[0] = down;
    io.KeyCtrl = ctrl;
    ImGui::NewFrame();
    draw_();
    ImGui::Render();
  }

  // The window named `name` (a panel's, a popup's), null when it never was.
  static ImGuiWindow* window(const std::string& name) {
    return ImGui::FindWindowByName(name.c_str());
  }
  // Whether that window was drawn in the last frame.
  static bool shown(const std::string& name) {
    const ImGuiWindow* w = window(name);
    return w != nullptr && w->Active;
  }
  // The ID ImGui gives the widget at `path` inside `seed` (a window's ID).
  static ImGuiID idIn(ImGuiID seed, std::initializer_list<IdPart> path) {
    for (const IdPart& p : path) {
      seed = p.isNumber ? ImHashData(&p.number, sizeof p.number, seed)
                        : ImHashStr(p.text.c_str(), 0, seed);
    }
    return seed;
  }
  // The window of a popup opened at `path` in window `name` (OpenPopup's
  // ID there; ImGui names the popup's window after it).
  static std::string popupWindow(const std::string& name, std::initializer_list<IdPart> path) {
    char popup[32];
    std::snprintf(popup, sizeof popup, "##Popup_%08x", idIn(window(name)->ID, path));
    return popup;
  }

  // The rectangle the widget at `path` in window `name` was drawn at, in
  // display units; empty (and a test failure) when it was not drawn.
  ImRect rectOf(const std::string& name, std::initializer_list<IdPart> path) {
    ImGuiWindow* w = window(name);
    if (w == nullptr) {
      ADD_FAILURE() << "no window " << name;
      return {};
    }
    const ImGuiID id = idIn(w->ID, path);
    ImGui::GetIO().MousePos = ImVec2(-FLT_MAX, -FLT_MAX);
    ImGui::NewFrame();
    ImGui::SetFocusID(id, w);
    draw_();
    ImGui::Render();
    if (!ImGui::GetCurrentContext()->NavIdIsAlive) {
      ADD_FAILURE() << "no widget " << describe(path) << " in " << name;
      return {};
    }
    return ImGui::WindowRectRelToAbs(w, w->NavRectRel[ImGuiNavLayer_Main]);
  }

  // Moves the mouse onto the widget, checks that it hovers that widget, and
  // clicks it (with Ctrl held: a drag's or slider's text input).
  void click(const std::string& name, std::initializer_list<IdPart> path, bool ctrl = false) {
    const ImRect r = rectOf(name, path);
    if (r.GetWidth() <= 0.0f) return;
    const ImVec2 at = r.GetCenter();
    hover(name, path, at);
    frame(at, true, ctrl);
    frame(at, false, ctrl);
  }
  // Presses on the widget's centre, moves by `by` in `steps` frames and
  // lets go there.
  void drag(const std::string& name, std::initializer_list<IdPart> path, ImVec2 by, int steps = 8) {
    const ImRect r = rectOf(name, path);
    if (r.GetWidth() <= 0.0f) return;
    const ImVec2 at = r.GetCenter();
    hover(name, path, at);
    frame(at, true);
    for (int i = 1; i <= steps; ++i) {
      const float f = static_cast<float>(i) / static_cast<float>(steps);
      frame(ImVec2(at.x + f * by.x, at.y + f * by.y), true);
    }
    frame(ImVec2(at.x + by.x, at.y + by.y), false);
  }
  // Characters typed into the widget being edited.
  void type(const char* text) {
    ImGui::GetIO().AddInputCharactersUTF8(text);
    frame();
  }
  // Ctrl+click on a slider or drag (its text input), `text` typed, and a
  // click away that ends the edit.
  void typeInto(const std::string& name, const char* label, const char* text) {
    click(name, {label}, true);
    type(text);
    clickAway();
  }
  // A click where no panel is (the 3D view's place): ends an edit, closes a
  // popup that is not modal.
  void clickAway() {
    const ImVec2 at(0.75f * kWidth, 0.5f * kHeight);
    frame(at);
    frame(at, true);
    frame(at, false);
  }

 private:
  static std::string describe(std::initializer_list<IdPart> path) {
    std::string s;
    for (const IdPart& p : path)
      s += (s.empty() ? "" : "/") + (p.isNumber ? std::to_string(p.number) : p.text);
    return s;
  }
  void hover(const std::string& name, std::initializer_list<IdPart> path, ImVec2 at) {
    frame(at);
    const ImGuiID id = idIn(window(name)->ID, path);
    EXPECT_EQ(ImGui::GetCurrentContext()->HoveredId, id)
        << "the mouse at (" << at.x << ", " << at.y << ") is not over " << describe(path);
  }

  std::function<void()> draw_;
  ImGuiContext* context_ = nullptr;
};

}  // namespace tessera::test
