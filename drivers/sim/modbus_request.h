#pragma once
// The register writes a raw Modbus request carries, as the turntable simulator needs them to
// act on a command before libmodbus answers it (functions 6, 16 and 23 of the Modbus
// Application Protocol v1.1b3, section 6).

#include <cstdint>
#include <vector>

namespace boxd {

// One register write found in a request: the registers it sets.
struct RegisterWrite {
    int address = 0;
    std::vector<uint16_t> values;
};

struct DecodedRequest {
    int function = 0;
    int lowest_register = 0;  // lowest register read or written (0 when unknown)
    std::vector<RegisterWrite> writes;
};

// Returns the function, the lowest register and the writes of the request `req` of `length`
// bytes whose ADU header is `header` bytes long.
DecodedRequest DecodeModbusRequest(const uint8_t* req, int length, int header);

// Returns true when `w` writes any register of lo..hi.
bool Touches(const RegisterWrite& w, int lo, int hi);

// Returns the value `w` writes to `address`, or -1.
int ValueAt(const RegisterWrite& w, int address);

}  // namespace boxd
