// Files dropped on a GlfwWindow by a real X drag-and-drop source: the test
// is the XDND source itself (a second X connection owning the XdndSelection
// and sending XdndEnter / XdndPosition / XdndDrop to GLFW's window), and it
// answers GLFW's request for the dropped data with a text/uri-list. So what
// runs is the whole way a file manager's drop takes into the viewer: GLFW's
// X11 code, its URI parsing (percent escapes, several files, comment lines)
// and GlfwWindow::onDrop's callback turning GLFW's `const char**` into the
// path list that the desktop viewer hands to desktop::filesDropped
// (tests/desktop/PanelsDropTest.cpp goes on from there). ctest runs it under
// xvfb-run (cmake/DesktopViewer.cmake); without a display it is skipped.
// GLFW's window is found by its title (glfw3native.h would need Xrandr's
// headers).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "tessera/gpu/GlfwWindow.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <X11/Xatom.h>
#include <X11/Xlib.h>

namespace tessera::gpu {
namespace {

// The drag source: its own connection and an unmapped window that owns the
// XdndSelection while the drag lasts.
class XdndSource {
 public:
  XdndSource() : display_(XOpenDisplay(nullptr)) {
    if (!display_) return;
    window_ = XCreateSimpleWindow(display_, DefaultRootWindow(display_), 0, 0, 1, 1, 0, 0, 0);
    for (const char* name : {"XdndAware", "XdndEnter", "XdndPosition", "XdndStatus", "XdndDrop",
                             "XdndFinished", "XdndSelection", "XdndActionCopy", "text/uri-list"}) {
      atoms_.push_back(XInternAtom(display_, name, False));
    }
    XSetSelectionOwner(display_, atom(kSelection), window_, CurrentTime);
    XFlush(display_);
  }
  ~XdndSource() {
    if (!display_) return;
    XDestroyWindow(display_, window_);
    XCloseDisplay(display_);
  }
  XdndSource(const XdndSource&) = delete;
  XdndSource& operator=(const XdndSource&) = delete;

  bool open() const { return display_ != nullptr; }

  // The top-level window titled `title` (GLFW's window: no window manager
  // runs under Xvfb, so it is a child of the root), or 0.
  Window windowTitled(const std::string& title) {
    Window root = 0, parent = 0;
    Window* children = nullptr;
    unsigned count = 0;
    Window found = 0;
    if (!XQueryTree(display_, DefaultRootWindow(display_), &root, &parent, &children, &count))
      return 0;
    for (unsigned i = 0; i < count && !found; ++i) {
      char* name = nullptr;
      if (XFetchName(display_, children[i], &name) && name) {
        if (title == name) found = children[i];
        XFree(name);
      }
    }
    if (children) XFree(children);
    return found;
  }

  // The XDND protocol version the target announces on its XdndAware
  // property (GLFW: 5), or nothing when the window takes no drops.
  std::optional<long> awareVersion(Window target) {
    Atom type = None;
    int format = 0;
    unsigned long count = 0, after = 0;
    unsigned char* data = nullptr;
    XGetWindowProperty(display_, target, atom(kAware), 0, 1, False, XA_ATOM, &type, &format, &count,
                       &after, &data);
    std::optional<long> version;
    if (data && count == 1 && format == 32)
      version = static_cast<long>(*reinterpret_cast<Atom*>(data));
    if (data) XFree(data);
    return version;
  }

  void enter(Window target) {
    send(target, kEnter,
         {static_cast<long>(window_), 5L << 24, static_cast<long>(atom(kUriList)), 0, 0});
  }
  void position(Window target, int rootX, int rootY) {
    send(target, kPosition,
         {static_cast<long>(window_), 0, (rootX << 16) | rootY, CurrentTime,
          static_cast<long>(atom(kActionCopy))});
  }
  void drop(Window target) {
    send(target, kDrop, {static_cast<long>(window_), 0, CurrentTime, 0, 0});
  }

  // Handles what reached the source: the target's status (accepted or not),
  // its request for the data (answered with `uriList`), its "finished".
  void serve(const std::string& uriList) {
    while (XPending(display_) > 0) {
      XEvent e;
      XNextEvent(display_, &e);
      if (e.type == ClientMessage && e.xclient.message_type == atom(kStatus)) {
        accepted = (e.xclient.data.l[1] & 1) != 0;
      } else if (e.type == ClientMessage && e.xclient.message_type == atom(kFinished)) {
        finished = true;
      } else if (e.type == SelectionRequest) {
        const XSelectionRequestEvent& r = e.xselectionrequest;
        ++requests;
        XEvent reply{};
        reply.xselection.type = SelectionNotify;
        reply.xselection.requestor = r.requestor;
        reply.xselection.selection = r.selection;
        reply.xselection.target = r.target;
        reply.xselection.time = r.time;
        reply.xselection.property = None;
        if (r.target == atom(kUriList)) {
          XChangeProperty(display_, r.requestor, r.property, r.target, 8, PropModeReplace,
                          reinterpret_cast<const unsigned char*>(uriList.data()),
                          static_cast<int>(uriList.size()));
          reply.xselection.property = r.property;
        }
        XSendEvent(display_, r.requestor, False, 0, &reply);
        XFlush(display_);
      }
    }
  }

  std::optional<bool> accepted;
  bool finished = false;
  int requests = 0;

 private:
  enum AtomIndex {
    kAware,
    kEnter,
    kPosition,
    kStatus,
    kDrop,
    kFinished,
    kSelection,
    kActionCopy,
    kUriList
  };
  Atom atom(AtomIndex i) const { return atoms_[static_cast<std::size_t>(i)]; }
  void send(Window target, AtomIndex type, std::vector<long> l) {
    XEvent e{};
    e.xclient.type = ClientMessage;
    e.xclient.display = display_;
    e.xclient.window = target;
    e.xclient.message_type = atom(type);
    e.xclient.format = 32;
    for (std::size_t i = 0; i < 5; ++i) e.xclient.data.l[i] = l[i];
    XSendEvent(display_, target, False, NoEventMask, &e);
    XFlush(display_);
  }

  Display* display_ = nullptr;
  Window window_ = 0;
  std::vector<Atom> atoms_;
};

class GlfwDrop : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (ctest runs this under xvfb-run)";
  }

  // Pumps the window's events and the source's until `done` holds (or 10 s).
  template <class Done>
  bool pumpUntil(GlfwWindow& window, XdndSource& source, const std::string& uriList, Done done) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < end) {
      window.pollEvents();
      source.serve(uriList);
      if (done()) return true;
    }
    return false;
  }

  // Drags `uriList` from a new source onto the window's centre and drops it;
  // the paths the window's drop handler was called with, one list per call.
  std::vector<std::vector<std::string>> dragAndDrop(const std::string& uriList) {
    GlfwWindow window({.width = 320, .height = 240, .title = "tessera drop test"});
    std::vector<std::vector<std::string>> calls;
    window.onDrop([&calls](const std::vector<std::string>& paths) { calls.push_back(paths); });
    glfwShowWindow(window.handle());
    window.pollEvents();
    XdndSource source;
    EXPECT_TRUE(source.open());
    if (!source.open()) return calls;
    const Window target = source.windowTitled("tessera drop test");
    EXPECT_NE(target, 0u) << "GLFW's window is not a child of the root";
    if (target == 0) return calls;
    EXPECT_EQ(source.awareVersion(target), std::optional<long>(5)) << "GLFW's window takes drops";
    int x = 0, y = 0;
    glfwGetWindowPos(window.handle(), &x, &y);
    source.enter(target);
    source.position(target, x + 160, y + 120);
    EXPECT_TRUE(pumpUntil(window, source, uriList, [&] { return source.accepted.has_value(); }))
        << "no XdndStatus from the window";
    EXPECT_EQ(source.accepted, std::optional<bool>(true)) << "the window refused a text/uri-list";
    source.drop(target);
    EXPECT_TRUE(pumpUntil(window, source, uriList, [&] { return source.finished; }))
        << "the window never finished the drop";
    EXPECT_EQ(source.requests, 1) << "the window asks for the data once";
    return calls;
  }
};

TEST_F(GlfwDrop, AFileManagersDropReachesTheHandlerAsDecodedPathsInOrder) {
  // A file manager's text/uri-list: CRLF lines, a comment, percent escapes
  // for a space and for UTF-8 (é = %C3%A9).
  const std::string uriList =
      "# dragged from a file manager\r\n"
      "file:///data/scans/anatomy%20T1.nii.gz\r\n"
      "file:///data/scans/atlas-%C3%A9tude.nii.gz\r\n"
      "file:///data/dicom/CT%20series\r\n";
  const auto calls = dragAndDrop(uriList);
  ASSERT_EQ(calls.size(), 1u) << "one drop, one call";
  EXPECT_EQ(calls[0], (std::vector<std::string>{"/data/scans/anatomy T1.nii.gz",
                                                "/data/scans/atlas-\xC3\xA9tude.nii.gz",
                                                "/data/dicom/CT series"}));
}

TEST_F(GlfwDrop, OneFileDroppedIsOnePath) {
  const auto calls = dragAndDrop("file:///tmp/head.nii.gz\r\n");
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_EQ(calls[0], (std::vector<std::string>{"/tmp/head.nii.gz"}));
}

}  // namespace
}  // namespace tessera::gpu
