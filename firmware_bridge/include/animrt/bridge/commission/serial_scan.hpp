#pragma once
// Safe queries on one serial line at one baud, per protocol: pings and
// reads only, so a scan never moves anything or switches torque on.

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/commission/found_device.hpp"

namespace animrt::commission {

// Standard baud rates of each family (their Baud Rate register's values).
const std::vector<int>& dynamixel_bauds();
const std::vector<int>& feetech_bauds();
const std::vector<int>& maestro_bauds();

// Dynamixel Protocol 2.0: one broadcast ping (answers collected for as long
// as ids up to limits.last_id may take to answer in turn), then a read of
// each answering servo's control table. Two answers with one id, or damaged
// answers whose header names an id, are reported as collisions.
void scan_dynamixel(ByteTransport& line, int baud, const ScanLimits& limits, ScanResult& out);

// Feetech SCS/STS: a unicast ping of each id in the limits, then a read of
// each answering servo's memory table.
void scan_feetech(ByteTransport& line, int baud, const ScanLimits& limits, ScanResult& out);

// Pololu Maestro: Get Errors (compact protocol). True if a board answered;
// servo packets are then not sent on that line (a Maestro would read a
// servo packet's bytes as Mini SSC commands).
bool scan_maestro(ByteTransport& line, int baud, const ScanLimits& limits, ScanResult& out);

}  // namespace animrt::commission
