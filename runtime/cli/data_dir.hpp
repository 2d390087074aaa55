#pragma once
// Where animrt's shipped data (models, gaits, grammars: the source tree's
// configs/) is, wherever it runs: never the working directory. From the
// build tree, the source tree's configs/; installed, the data folder beside
// the executable's prefix (PREFIX/share/animrt), else the one configured
// at build time.

#include <string>

namespace animrt::cli {

std::string data_dir();

// The dashboard's page: the source tree's runtime/dashboard/www from the
// build tree, else the data folder's www/.
std::string dashboard_www_dir();

}  // namespace animrt::cli
