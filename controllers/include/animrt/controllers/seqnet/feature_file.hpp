#pragma once
// The versioned binary feature file (layout in docs/seqnet.md): template
// mesh, clips, normalisation mapping and normalised features, with a CRC-32
// so that a corrupt file is an error rather than wrong numbers.

#include <string>

#include "animrt/controllers/seqnet/features.hpp"

namespace animrt::seqnet {

constexpr char kFeatureFileMagic[8] = {'A', 'N', 'S', 'E', 'Q', 'F', 'T', '\n'};
constexpr std::uint32_t kFeatureFileVersion = 2;  // 2 added the placement; 1 is still read

// Throws std::runtime_error when the file cannot be written.
void write_feature_file(const std::string& file, const SequenceFeatures& features);
// Throws InputError naming the file and the part (header, clip N, frame N,
// checksum) for a file that is truncated, corrupt or of another version.
SequenceFeatures read_feature_file(const std::string& file);

}  // namespace animrt::seqnet
