// The viewer's window, mouse camera: see viewer_window.h.
#include "app/viewer_window.h"

#include <GL/glew.h>
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <ostream>

#include "app/cli.h"

namespace sylva::app {

Window::~Window() {
  if (!handle) return;
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(handle);
  glfwTerminate();
}

int OpenWindow(int width, int height, const std::string& title, bool vsync, Window& w,
               std::ostream& err) {
  if (!glfwInit()) {
    err << "sylva: error: cannot open a window (no display? run under Xvfb, or use sylva render)\n";
    return kExitRuntime;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWwindow* window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window) {
    glfwTerminate();
    err << "sylva: error: cannot create an OpenGL 4.5 window\n";
    return kExitRuntime;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(vsync ? 1 : 0);
  glewExperimental = GL_TRUE;
  if (glewInit() != GLEW_OK) {
    glfwDestroyWindow(window);
    glfwTerminate();
    err << "sylva: error: cannot load OpenGL functions\n";
    return kExitRuntime;
  }
  glGetError();
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui::StyleColorsLight();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 450 core");
  w.handle = window;
  return kExitOk;
}

void MouseCamera::Update(GLFWwindow* window, render::Camera& camera) {
  const ImGuiIO& io = ImGui::GetIO();
  double mx, my;
  glfwGetCursorPos(window, &mx, &my);
  // A drag belongs to the camera only if its button went down off the
  // panel: a click or drag that starts on the panel (a slider moved past
  // the panel's edge) never also turns the view.
  const bool left = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  const bool right = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
  if (left && !leftDown) leftOrbits = !io.WantCaptureMouse;
  if (right && !rightDown) rightPans = !io.WantCaptureMouse;
  leftDown = left;
  rightDown = right;
  if (left && leftOrbits) {
    camera.azimuth -= (mx - lastX) * 0.4;
    camera.elevation = std::clamp(camera.elevation + (my - lastY) * 0.4, -85.0, 85.0);
  }
  if (right && rightPans) {
    const Mat4 v = camera.View();
    const Vec3 r(v(0, 0), v(0, 1), v(0, 2)), up(v(1, 0), v(1, 1), v(1, 2));
    // In parallel projection the view is orthoHeight units high: the
    // target follows the cursor exactly.
    int windowWidth = 0, windowHeight = 0;
    glfwGetWindowSize(window, &windowWidth, &windowHeight);
    const double k = camera.orthographic ? camera.orthoHeight / std::max(windowHeight, 1)
                                         : camera.distance * 0.0015;
    camera.target += (-r * (mx - lastX) + up * (my - lastY)) * k;
  }
  // The wheel zooms (render::Camera::Zoom).
  if (!io.WantCaptureMouse && io.MouseWheel != 0) camera.Zoom(std::pow(0.9, io.MouseWheel));
  lastX = mx;
  lastY = my;
}

}  // namespace sylva::app
