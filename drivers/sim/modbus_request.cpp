#include "drivers/sim/modbus_request.h"

#include <modbus/modbus.h>

#include <algorithm>
#include <utility>

namespace boxd {

namespace {

uint16_t Word(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }

}  // namespace

DecodedRequest DecodeModbusRequest(const uint8_t* req, int length, int header) {
    DecodedRequest d;
    if (length < header + 5) return d;
    const uint8_t* pdu = req + header;
    d.function = pdu[0];
    const int address = Word(pdu + 1);
    d.lowest_register = address;
    if (d.function == MODBUS_FC_WRITE_SINGLE_REGISTER) {
        d.writes.push_back({address, {Word(pdu + 3)}});
    } else if (d.function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS && length >= header + 6) {
        const int count = Word(pdu + 3);
        if (length >= header + 6 + 2 * count) {
            RegisterWrite w{address, {}};
            for (int i = 0; i < count; ++i) w.values.push_back(Word(pdu + 6 + 2 * i));
            d.writes.push_back(std::move(w));
        }
    } else if (d.function == MODBUS_FC_WRITE_AND_READ_REGISTERS && length >= header + 10) {
        const int write_address = Word(pdu + 5);
        const int count = Word(pdu + 7);
        if (length >= header + 10 + 2 * count) {
            RegisterWrite w{write_address, {}};
            for (int i = 0; i < count; ++i) w.values.push_back(Word(pdu + 10 + 2 * i));
            d.writes.push_back(std::move(w));
            d.lowest_register = std::min(address, write_address);
        }
    }
    return d;
}

bool Touches(const RegisterWrite& w, int lo, int hi) {
    const int last = w.address + static_cast<int>(w.values.size()) - 1;
    return w.address <= hi && last >= lo;
}

int ValueAt(const RegisterWrite& w, int address) {
    const int i = address - w.address;
    if (i < 0 || i >= static_cast<int>(w.values.size())) return -1;
    return w.values[static_cast<std::size_t>(i)];
}

}  // namespace boxd
