#!/usr/bin/env python3
# The lcm_datagram fuzz seeds (fuzz/corpus/README.md): records of (sender byte, uint16 length,
# datagram) in LCM's UDP format (common/lcm_datagram.hpp).
#   python3 fuzz/lcm_datagram_seeds.py fuzz/corpus/lcm_datagram
import struct, sys, os
out = sys.argv[1]
def rec(sender, d): return bytes([sender]) + struct.pack('>H', len(d)) + d
def short(seq, ch, p): return struct.pack('>II', 0x4c433032, seq) + ch + b'\0' + p
def frag(seq, size, off, no, n, ch, p):
    return struct.pack('>IIIIHH', 0x4c433033, seq, size, off, no, n) + (ch + b'\0' if no == 0 else b'') + p
msg = bytes(range(256)) * 12  # 3072 bytes
open(os.path.join(out, 'short.bin'), 'wb').write(rec(1, short(7, b'CAMERA_LEFT', b'\x01\x02\x03' * 20)))
open(os.path.join(out, 'three_fragments.bin'), 'wb').write(
    rec(1, frag(8, 3072, 0, 0, 3, b'CAMERA_LEFT', msg[:1000])) +
    rec(1, frag(8, 3072, 1000, 1, 3, b'', msg[1000:2000])) +
    rec(1, frag(8, 3072, 2000, 2, 3, b'', msg[2000:])))
open(os.path.join(out, 'two_senders_lost.bin'), 'wb').write(
    rec(1, frag(9, 3072, 0, 0, 3, b'CAMERA_LEFT', msg[:1000])) +
    rec(2, frag(3, 3072, 0, 0, 3, b'CAMERA_RIGHT', msg[:1000])) +
    rec(1, frag(9, 3072, 2000, 2, 3, b'', msg[2000:])) +
    rec(2, frag(3, 3072, 1000, 1, 3, b'', msg[1000:2000])) +
    rec(3, short(1, b'OBJECT_POSITION', b'\0' * 40)) +
    rec(2, frag(3, 3072, 2000, 2, 3, b'', msg[2000:])))
