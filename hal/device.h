// Vocabulary shared by every device interface: identity and link state.
#pragma once

#include <string>

namespace replica::hal {

enum class LinkState { Connected, Stalled, Lost };

inline const char* toString(LinkState s)
{
    switch (s) {
    case LinkState::Connected:
        return "connected";
    case LinkState::Stalled:
        return "stalled";
    case LinkState::Lost:
        return "lost";
    }
    return "unknown";
}

// Which implementation stands behind an interface.
enum class SourceKind { Live, Sim, Replay };

inline const char* toString(SourceKind k)
{
    switch (k) {
    case SourceKind::Live:
        return "live";
    case SourceKind::Sim:
        return "sim";
    case SourceKind::Replay:
        return "replay";
    }
    return "unknown";
}

struct DeviceInfo {
    std::string model;    // e.g. "USB2000+", "sim-spectrometer"
    std::string serial;   // device serial, or a fixed string for sim/replay
    std::string firmware; // firmware version if the device reports one
    SourceKind kind = SourceKind::Sim;
};

} // namespace replica::hal
