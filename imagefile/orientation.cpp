// EXIF/TIFF orientation applied to decoded pixels, as OpenCV applied it.
#include "imagefile/image_file.h"

namespace impactlab::imagefile {

void ApplyExifOrientation(int orientation, cv::Mat& image) {
  switch (orientation) {
    case 2:  // top right: mirrored
      cv::flip(image, image, 1);
      break;
    case 3:  // bottom right: turned half round
      cv::flip(image, image, -1);
      break;
    case 4:  // bottom left: upside down
      cv::flip(image, image, 0);
      break;
    case 5:  // left top: transposed
      cv::transpose(image, image);
      break;
    case 6:  // right top: turned a quarter clockwise
      cv::transpose(image, image);
      cv::flip(image, image, 1);
      break;
    case 7:  // right bottom
      cv::transpose(image, image);
      cv::flip(image, image, -1);
      break;
    case 8:  // left bottom: turned a quarter counter-clockwise
      cv::transpose(image, image);
      cv::flip(image, image, 0);
      break;
    default:  // 1 (as stored) or not an orientation
      break;
  }
}

}  // namespace impactlab::imagefile
