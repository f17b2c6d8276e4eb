#pragma once

#include <string>
#include <vector>

namespace sg::vision {

/// The image files (png, jpg, jpeg, bmp, ppm; any case) in a folder, sorted by name, so that two
/// folders of a stereo pair line up by name. Throws std::runtime_error when `dir` is not a folder
/// or holds no images.
std::vector<std::string> list_images(const std::string& dir);

}  // namespace sg::vision
