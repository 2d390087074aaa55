#pragma once
// Where animrt's shipped data (models, gaits, grammars: the source tree's
// configs/) is, wherever it runs: never the working directory. From the
// build tree, the source tree's configs/; installed, the data folder beside
// the executable's prefix (PREFIX/share/animrt), else the one configured
// at build time.

#include <string>

namespace animrt::cli {

std::string data_dir();

}  // namespace animrt::cli
