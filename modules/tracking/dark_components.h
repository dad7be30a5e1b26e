// Module-internal: the candidates of DetectDots (dot_detector.h, step 1), the 8-connected components of the
// dark pixels of a frame, found in one pass over its rows. A row's dark mask is made and labelled as runs
// of dark pixels straight away, so no frame-sized mask or label image is kept. Pixel conventions as
// dot_detector.h.
#pragma once

#include <vector>

#include <visp3/core/vpImage.h>

#include "tracking/dot_detector.h"

namespace selfcal::tracking::internal {

// One 8-connected component of dark pixels.
struct Component {
  int count = 0;
  PixelBox bbox{1 << 30, 1 << 30, -1, -1};
  int darkest_u = -1, darkest_v = -1;  // first darkest pixel in raster order
  int darkest = 256;
};

// Dark: I <= threshold. Components in raster order of their first pixel.
std::vector<Component> GlobalDarkComponents(const vpImage<unsigned char>& image, int threshold);

// Dark: I <= (mean of the window x window box around the pixel, clipped to the image) - offset, tested in
// integers as n I + n offset <= box sum. `window` odd >= 3. Components in raster order of their first
// pixel. The sums are kept in 16, 32 or 64 bits, chosen up front from the image size and window so that
// none can overflow; the result does not depend on the choice.
std::vector<Component> AdaptiveDarkComponents(const vpImage<unsigned char>& image, int window, int offset);

// The same with the sums forced to 64 bits (the reference the narrower sums are tested against).
std::vector<Component> AdaptiveDarkComponentsWide(const vpImage<unsigned char>& image, int window, int offset);

}  // namespace selfcal::tracking::internal
