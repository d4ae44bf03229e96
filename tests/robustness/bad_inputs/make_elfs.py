#!/usr/bin/env python3
# Writes the crafted RV32 ELFs files/elf_*.elf that elf.tsv runs (the outputs are committed; run
# it again only to change them): python3 make_elfs.py files
import struct, sys, os
out = sys.argv[1]
EXIT0 = [0x00000513, 0x05d00893, 0x00000073]  # li a0,0; li a7,93; ecall
EBREAK = 0x00100073
SW_X0_M4_T0 = (0x7f << 25) | (5 << 15) | (2 << 12) | (0x1c << 7) | 0x23  # sw x0,-4(t0)
def words(ws): return b''.join(struct.pack('<I', w) for w in ws)
def jump_to(addr):  # lui t0,addr>>12; jalr x0,0(t0)
    return words([(addr & 0xfffff000) | (5 << 7) | 0x37, (5 << 15) | 0x67])
R, W, X = 4, 2, 1
def elf(segs, entry, etype=2, flags=2, machine=243, data=1):
    # segs: (vaddr, p_flags, file bytes[, p_memsz or None, p_offset or None, p_type]), one
    # program header each; the file bytes follow the headers in order.
    phoff = 52
    off = phoff + 32 * len(segs)
    body = b''; phdrs = b''
    for s in segs:
        vaddr, pf, blob, memsz, offover, ptype = tuple(s) + (None, None, 1)[len(s) - 3:]
        memsz = len(blob) if memsz is None else memsz
        o = off + len(body) if offover is None else offover
        phdrs += struct.pack('<8I', ptype, o, vaddr, vaddr, len(blob), memsz, pf, 4)
        body += blob
    ident = b'\x7fELF' + bytes([1, data, 1, 0]) + bytes(8)
    eh = ident + struct.pack('<HHIIIIIHHHHHH', etype, machine, 1, entry, phoff, 0, flags,
                             52, 32, len(segs), 40, 0, 0)
    return eh + phdrs + body
files = {
  # memsz far past the end of the program area
  'elf_huge_memsz.elf': elf([(0x10000, R | X, words(EXIT0), 0xfff00000)], 0x10000),
  # a data segment of 255 MiB that fits below global memory (accepted: must run, not stall)
  # (stores to its last word, then ebreak: the breakpoint line shows it ran)
  'elf_big_bss.elf': elf([(0x10000, R | X, words([0x100002b7, SW_X0_M4_T0, EBREAK])),
                          (0x20000, R | W, b'', 0x0ffe0000)], 0x10000),
  'elf_overlap.elf': elf([(0x10000, R | X, words(EXIT0) * 4), (0x10010, R, words(EXIT0))],
                         0x10000),
  'elf_entry_in_data.elf': elf([(0x10000, R | X, words(EXIT0)), (0x20000, R | W, words(EXIT0))],
                               0x20000),
  'elf_entry_outside.elf': elf([(0x10000, R | X, words(EXIT0))], 0x40000),
  'elf_entry_misaligned.elf': elf([(0x10000, R | X, words(EXIT0))], 0x10002),
  'elf_filesz_gt_memsz.elf': elf([(0x10000, R | X, words(EXIT0), 8)], 0x10000),
  'elf_segment_past_file.elf': elf([(0x10000, R | X, words(EXIT0), None, 0xfffffff0)], 0x10000),
  'elf_wx.elf': elf([(0x10000, R | W | X, words(EXIT0))], 0x10000),
  'elf_below_code_base.elf': elf([(0x1000, R | X, words(EXIT0))], 0x1000),
  'elf_no_load.elf': elf([(0x10000, R, words(EXIT0), None, None, 4)], 0x10000),
  'elf_rvc.elf': elf([(0x10000, R | X, words(EXIT0))], 0x10000, flags=3),
  'elf_relocatable.elf': elf([(0x10000, R | X, words(EXIT0))], 0x10000, etype=1),
  'elf_big_endian.elf': elf([(0x10000, R | X, words(EXIT0))], 0x10000, data=2),
  # code at both ends of the program area, 256 MiB apart (accepted: the gap is not decoded;
  # the far code is an ebreak)
  'elf_code_gap.elf': elf([(0x10000, R | X, jump_to(0x0ffff000)),
                           (0x0ffff000, R | X, words([EBREAK]))], 0x10000),
  # code jumps into a readable, non-executable segment between two code segments
  'elf_jump_into_data.elf': elf([(0x10000, R | X, jump_to(0x20000)),
                                 (0x20000, R, words(EXIT0)),
                                 (0x30000, R | X, words(EXIT0))], 0x10000),
  # an executable segment with no file bytes: all zero fill, where the entry lies
  'elf_exec_zero_fill.elf': elf([(0x10000, R | X, b'', 0x1000)], 0x10000),
}
for name, blob in files.items():
    with open(os.path.join(out, name), 'wb') as f: f.write(blob)
print(len(files), 'files')
