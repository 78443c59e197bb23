// Is a PNG a figure and not a blank canvas? Width, height and the standard deviation of its pixel
// values, read by Debian's matplotlib (the plots' own dependency), so no image library is needed.
#pragma once
#include <cstdio>
#include <filesystem>
#include <string>

namespace gravsweep::test {

struct PngStats {
  int width = 0, height = 0;
  double pixel_std = 0;  ///< over all channels, values in [0, 1]; a blank canvas gives 0
  bool ok = false;
};

inline PngStats png_stats(const std::filesystem::path& png) {
  PngStats s;
  const std::string cmd =
      "/usr/bin/python3 -c \"import sys, matplotlib.image as m; a = m.imread(sys.argv[1]); "
      "print(a.shape[1], a.shape[0], float(a[..., :3].std()))\" '" +
      png.string() + "' 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return s;
  s.ok = std::fscanf(p, "%d %d %lf", &s.width, &s.height, &s.pixel_std) == 3;
  pclose(p);
  return s;
}

}  // namespace gravsweep::test
