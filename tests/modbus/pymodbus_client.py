"""An independent Modbus master (pymodbus, Debian's python3-pymodbus) against
the simulated drives: reads registers, provokes exceptions 2 and 3.

usage: /usr/bin/python3 pymodbus_client.py tcp HOST:PORT | rtu PTY_PATH
Prints one line per check, "name value".
"""
import logging
import sys

logging.disable(logging.CRITICAL)

from pymodbus.client import ModbusSerialClient, ModbusTcpClient  # noqa: E402


def main():
    kind, where = sys.argv[1], sys.argv[2]
    if kind == "tcp":
        host, port = where.rsplit(":", 1)
        client = ModbusTcpClient(host, port=int(port), timeout=2)
    else:
        client = ModbusSerialClient(port=where, baudrate=19200, parity="N", timeout=2)
    if not client.connect():
        print("connect failed")
        return 1
    # Slave 2 (linear actuator): present + status at holding 20..21.
    rr = client.read_holding_registers(20, 2, slave=2)
    print("present_status", "error" if rr.isError() else " ".join(str(v) for v in rr.registers))
    # Goal 0.2 m = 20000 counts, past the 0.1 m stroke: exception 3.
    rr = client.write_register(10, 20000, slave=2)
    print("exception_value", getattr(rr, "exception_code", "none"))
    # A register the drive does not have: exception 2.
    rr = client.read_holding_registers(500, 1, slave=2)
    print("exception_address", getattr(rr, "exception_code", "none"))
    # A goal inside the stroke is accepted and reads back.
    rr = client.write_register(10, 5000, slave=2)
    print("write_ok", "no" if rr.isError() else "yes")
    rr = client.read_holding_registers(10, 1, slave=2)
    print("goal", "error" if rr.isError() else rr.registers[0])
    client.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
