"""Write tangential contact histories into a LIGGGHTS 3.8 restart file (in place of the zeros
that `run 0; write_restart` leaves for every touching pair).

Per-atom restart record of atom_style granular in 3.8 (doubles, little endian):
  [0] size  [1..3] x  [4] tag(int64 bits)  [5] type  [6] mask  [7] image  [8..10] v
  [11] radius  [12] rmass  [13] density  [14..16] omega  then one chunk per fix with
  per-atom restart data, each chunk [n, n-1 values].  fix contacthistory's chunk is
  [ (dnum+1)*np + 2, np, (partner tag, dnum history values) x np ]  (fix_contact_history.cpp
  pack_restart), dnum = 3 (shearx, sheary, shearz) for `tangential history`;
  fix property/atom history_<wall> chunks are [4, h1, h2, h3].
Both atoms of a pair store the contact: atom i holds xi_ij, atom j holds -xi_ij
(newtonflag 1 for the shear values), so both are written.
"""
import struct

DNUM = 3

def _i(b, off):
    return struct.unpack_from('<q', b, off)[0]

def _d(b, off):
    return struct.unpack_from('<d', b, off)[0]

def patch(src, dst, grains, hist_pairs, L=None):
    b = bytearray(open(src, 'rb').read())
    # locate every atom's record by its exact position and tag
    rec = {}
    for g in grains:
        gid, x, y = g[0], g[1], g[2]
        if L: x = x % L
        pat = struct.pack('<dddq', x, y, 0.0, gid)
        k = b.find(pat)
        if k < 0 or b.find(pat, k + 1) >= 0:
            raise SystemExit('patch_restart: atom %d not found exactly once' % gid)
        rec[gid] = k - 8  # start of the record (its size)
    # per atom: offsets of its contact-history entries, by partner tag
    slots = {}
    for gid, k in rec.items():
        size = int(_d(b, k))
        m = 17  # first fix chunk
        found = None
        while m < size:
            n = int(_d(b, k + 8 * m))
            if n >= 2 and (n - 2) % (DNUM + 1) == 0 and _i(b, k + 8 * (m + 1)) == (n - 2) // (DNUM + 1):
                if found is not None:
                    raise SystemExit('patch_restart: two contact-history-like chunks in atom %d' % gid)
                found = m
            m += n
        if m != size:
            raise SystemExit('patch_restart: record of atom %d does not parse' % gid)
        if found is None:
            raise SystemExit('patch_restart: no contact-history chunk in atom %d' % gid)
        np_ = _i(b, k + 8 * (found + 1))
        for p in range(np_):
            off = k + 8 * (found + 2 + p * (DNUM + 1))
            slots[(gid, _i(b, off))] = off + 8
    done = 0
    for (i, j), xi in hist_pairs.items():
        for a, c, s in ((i, j, 1.0), (j, i, -1.0)):
            if (a, c) not in slots:
                raise SystemExit('patch_restart: history given for %d-%d, which LIGGGHTS does not see touching' % (i, j))
            struct.pack_into('<3d', b, slots[(a, c)], *(s * v for v in xi))
        done += 1
    open(dst, 'wb').write(bytes(b))
    print('patch_restart: %d pair histories written (%d pair contacts in the restart)' % (done, len(slots) // 2))
