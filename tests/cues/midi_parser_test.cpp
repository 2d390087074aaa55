// A raw MIDI byte stream as a rawmidi device delivers it: running status,
// real-time bytes inside messages, SysEx and system common messages skipped,
// stray data bytes counted; and which cue a message asks for.

#include <gtest/gtest.h>

#include "animrt/runtime/midi_input.hpp"

namespace animrt {
namespace {

std::vector<MidiMessage> midi_parse(MidiParser& parser, std::vector<std::uint8_t> bytes) {
  std::vector<MidiMessage> out;
  for (std::uint8_t b : bytes) {
    MidiMessage m;
    if (parser.feed(b, m)) out.push_back(m);
  }
  return out;
}

TEST(MidiParser, RunningStatusRealTimeAndSysEx) {
  MidiParser parser;
  const auto messages =
      midi_parse(parser, {0x40, 0x90, 60, 0xF8, 100,  62, 0xFA, 0, 0xF0, 1, 2,    3,  0xF7,
                          64,   0xC3, 5,  6,    0xF2, 1,  2,    7, 0xB0, 7, 0xFE, 100});
  ASSERT_EQ(messages.size(), 5u);
  EXPECT_EQ(messages[0].status, 0x90);
  EXPECT_EQ(messages[0].data1, 60);
  EXPECT_EQ(messages[0].data2, 100);
  EXPECT_EQ(messages[1].data1, 62);  // running status
  EXPECT_EQ(messages[1].data2, 0);
  EXPECT_EQ(messages[2].status, 0xC3);
  EXPECT_EQ(messages[2].data1, 5);
  EXPECT_EQ(messages[3].data1, 6);  // running status, one data byte
  EXPECT_EQ(messages[4].status, 0xB0);
  EXPECT_EQ(messages[4].data2, 100);
  // 0x40 before any status, 64 after the SysEx (which cancels running
  // status), 7 after the song position pointer (which does too).
  EXPECT_EQ(parser.malformed(), 3u);
  EXPECT_EQ(parser.sysex(), 1u);
}

TEST(MidiParser, NotesAndProgramsSelectCuesByChannel) {
  const std::vector<MidiBinding> bindings = {{1, false, 60, 0}, {2, false, 61, 3}, {3, true, 7, 0}};
  EXPECT_EQ(midi_cue({0x95, 60, 1}, bindings), 1);
  EXPECT_EQ(midi_cue({0x95, 60, 0}, bindings), -1);  // velocity 0: a note off
  EXPECT_EQ(midi_cue({0x85, 60, 64}, bindings), -1);
  EXPECT_EQ(midi_cue({0x92, 61, 1}, bindings), 2);  // channel 3
  EXPECT_EQ(midi_cue({0x93, 61, 1}, bindings), -1);
  EXPECT_EQ(midi_cue({0xCF, 7, 0}, bindings), 3);
  EXPECT_EQ(midi_cue({0xCF, 60, 0}, bindings), -1);
}

}  // namespace
}  // namespace animrt
