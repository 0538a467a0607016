// PNG output of `rccx plot`: the SVG that view::plot_svg makes, rendered by librsvg onto a cairo
// image surface. Only in builds that found librsvg when configured (RCCX_HAVE_RSVG); it lives in
// tools/ so that the view library and the installed rccx package do not depend on librsvg.
#pragma once

#include <string>
#include <string_view>

namespace rccx::tools {

/// The PNG file's bytes of `svg` at its own size in px (width and height of its <svg>), on
/// white. Throws io::FileError when librsvg cannot read the SVG or cairo cannot render it.
std::string svg_to_png(std::string_view svg);

}  // namespace rccx::tools
