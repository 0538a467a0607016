#include "plot_png.hpp"

#include <cairo.h>
#include <fmt/format.h>
#include <librsvg/rsvg.h>

#include <cmath>
#include <memory>

#include "rccx/io/file.hpp"

namespace rccx::tools {

namespace {

struct GObjectFree {
  void operator()(RsvgHandle* h) const noexcept { g_object_unref(h); }
};
struct SurfaceFree {
  void operator()(cairo_surface_t* s) const noexcept { cairo_surface_destroy(s); }
};
struct CairoFree {
  void operator()(cairo_t* c) const noexcept { cairo_destroy(c); }
};

cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

std::string svg_to_png(std::string_view svg) {
  GError* error = nullptr;
  std::unique_ptr<RsvgHandle, GObjectFree> handle(
      rsvg_handle_new_from_data(reinterpret_cast<const guint8*>(svg.data()), svg.size(), &error));
  if (!handle) {
    const std::string why = error != nullptr ? error->message : "unknown error";
    if (error != nullptr) g_error_free(error);
    throw io::FileError(fmt::format("librsvg cannot read the plot's SVG: {}", why));
  }
  double w = 0.0, h = 0.0;
  if (rsvg_handle_get_intrinsic_size_in_pixels(handle.get(), &w, &h) == FALSE || !(w >= 1.0) ||
      !(h >= 1.0)) {
    throw io::FileError("the plot's SVG has no size in px");
  }
  std::unique_ptr<cairo_surface_t, SurfaceFree> surface(cairo_image_surface_create(
      CAIRO_FORMAT_ARGB32, static_cast<int>(std::ceil(w)), static_cast<int>(std::ceil(h))));
  std::unique_ptr<cairo_t, CairoFree> cr(cairo_create(surface.get()));
  if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS) {
    throw io::FileError(fmt::format("cairo cannot make a {:.0f} x {:.0f} px image: {}", w, h,
                                    cairo_status_to_string(cairo_status(cr.get()))));
  }
  const RsvgRectangle viewport{0.0, 0.0, w, h};
  if (rsvg_handle_render_document(handle.get(), cr.get(), &viewport, &error) == FALSE) {
    const std::string why = error != nullptr ? error->message : "unknown error";
    if (error != nullptr) g_error_free(error);
    throw io::FileError(fmt::format("librsvg cannot render the plot: {}", why));
  }
  cairo_surface_flush(surface.get());
  std::string png;
  if (cairo_surface_write_to_png_stream(surface.get(), append, &png) != CAIRO_STATUS_SUCCESS) {
    throw io::FileError("cairo cannot encode the plot as PNG");
  }
  return png;
}

}  // namespace rccx::tools

// fontconfig (librsvg's text, through pango) keeps its caches until the process ends, by design;
// LeakSanitizer (the sanitizer build `make test` uses) would report them as leaks of rccx plot.
// This hook, read by LeakSanitizer alone, says they are not ours; it changes nothing else.
extern "C" const char* __lsan_default_suppressions();  // NOLINT(bugprone-reserved-identifier)
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libfontconfig.so\n";
}
extern "C" const char* __lsan_default_options();  // NOLINT(bugprone-reserved-identifier)
extern "C" const char* __lsan_default_options() {
  return "print_suppressions=0";
}
