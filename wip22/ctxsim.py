#!/usr/bin/env python3
"""Simulate the residual coding cost under alternative context models (issue 22 experiment)."""
import sys, struct, math
import numpy as np

def load(path):
    b = open(path, 'rb').read()
    V, r = struct.unpack_from('<ii', b, 0)
    off = np.frombuffer(b, '<i4', V + 1, 8)
    npos = off[-1]
    pos = np.frombuffer(b, '<i4', npos, 8 + 4 * (V + 1))
    steps = np.frombuffer(b, '<f8', V * r, 8 + 4 * (V + 1) + 4 * npos).reshape(r, V)
    return V, r, off, pos, steps

LOG = [0.0] * 4097
for i in range(4097):
    LOG[i] = -math.log2(max(i, 1) / 4096.0)

class Bit:
    __slots__ = ('f', 's', 'c')
    def __init__(self):
        self.f = 32768; self.s = 32768; self.c = 0
    def code(self, bit):
        p0 = (self.f + self.s) >> 1
        cost = LOG[(p0 if bit == 0 else 65536 - p0) >> 4]
        sf = min(1 + self.c, 4); ss = min(1 + self.c, 7)
        if bit == 0:
            self.f += (65536 - self.f) >> sf; self.s += (65536 - self.s) >> ss
        else:
            self.f -= self.f >> sf; self.s -= self.s >> ss
        if self.c < 6: self.c += 1
        return cost

class Ints:
    def __init__(self):
        self.zero = Bit(); self.sign = Bit(); self.greater = [Bit() for _ in range(14)]
        self.escape = [Bit() for _ in range(8)]
    def code(self, v):
        bits = self.zero.code(1 if v == 0 else 0)
        if v == 0: return bits
        bits += self.sign.code(1 if v < 0 else 0)
        m = abs(v) - 1
        for i in range(14):
            g = 1 if m > i else 0
            bits += self.greater[i].code(g)
            if not g: return bits
        e1 = m - 14 + 1
        n = e1.bit_length() - 1
        for k in range(n): bits += self.escape[min(k, 7)].code(1)
        bits += self.escape[min(n, 7)].code(0)
        return bits + n

def group(k):
    return k if k < 16 else min(16 + (k - 16) // 16, 23)

def simulate(data, ctxfn, nctx):
    V, r, off, pos, steps = data
    q = np.rint(steps)  # ties: llround rounds half away; negligible
    q = np.where(np.abs(steps - np.trunc(steps)) == 0.5, np.trunc(steps) + np.sign(steps), q).astype(np.int64)
    aq = np.abs(q)
    # neighbour sums per column, vectorised: sum over earlier neighbours of |q| in same column
    cnt = np.diff(off)
    owner = np.repeat(np.arange(V), cnt)
    models = {}
    total = 0.0
    for k in range(r):
        nsum = np.bincount(owner, weights=aq[k][pos], minlength=V) if len(pos) else np.zeros(V)
        prev1 = aq[k - 1] if k >= 1 else np.zeros(V, np.int64)
        prev2 = aq[k - 2] if k >= 2 else np.zeros(V, np.int64)
        ctx = ctxfn(k, nsum, cnt, prev1, prev2)
        qk = q[k].tolist(); ck = ctx.tolist()
        for i in range(V):
            key = ck[i]
            m = models.get(key)
            if m is None:
                m = models[key] = Ints()
            total += m.code(qk[i])
    return total

def bucket_old(nsum, cnt):
    mean = np.where(cnt > 0, (2 * nsum + cnt) // np.maximum(2 * cnt, 1), 0).astype(np.int64)
    bw = np.array([int(x).bit_length() for x in mean.tolist()]) if False else np.floor(np.log2(np.maximum(mean, 1))).astype(np.int64) + (mean > 0)
    b = np.minimum(4, bw + 1)
    return np.where((cnt == 0) | (nsum == 0), 0, b)

def ctx_old(k, nsum, cnt, p1, p2):
    return group(k) * 100 + bucket_old(nsum, cnt)

def logbucket(x, scale, nb):
    # 0 for x == 0; else 1 + floor(scale*log2(1+x)) capped
    return np.minimum(nb - 1, np.where(x <= 0, 0, 1 + np.floor(scale * np.log2(1.0 + x)).astype(np.int64)))

def make_ctx(wn=2.0, wp1=1.0, wp2=0.5, scale=2.0, nb=12, groups=True):
    def f(k, nsum, cnt, p1, p2):
        mean = np.where(cnt > 0, nsum / np.maximum(cnt, 1), 0.0)
        wsum = wn * mean + wp1 * p1 + wp2 * p2
        wt = wn * (cnt > 0) + wp1 * (k >= 1) + wp2 * (k >= 2)
        a = np.where(wt > 0, wsum / np.maximum(wt, 1e-9), 0.0)
        g = group(k) if groups else 0
        return g * 100 + logbucket(a * 4, 1.0 / scale * 2, nb) + 50 * ((cnt == 0) & (k == 0))
    return f

def make_ctx2d(nb_n=6, nb_p=4, scale=1.0):
    def f(k, nsum, cnt, p1, p2):
        mean = np.where(cnt > 0, nsum / np.maximum(cnt, 1), 0.0)
        bn = np.where(cnt == 0, nb_n, logbucket(mean * 2, scale, nb_n))
        bp = logbucket((p1 + 0.5 * p2), scale, nb_p)
        return group(k) * 1000 + bn * 10 + bp
    return f

if __name__ == '__main__':
    data = load(sys.argv[1])
    V, r = data[0], data[1]
    base = simulate(data, ctx_old, 0)
    print(f"{sys.argv[1]}: V={V} r={r} old: {base/8:.0f} B ({base/(V*r):.3f} bits/sym)")
    variants = {
        '2d n6 p4': make_ctx2d(6, 4),
        '2d n8 p5': make_ctx2d(8, 5),
        '2d n6 p1 (finer nbr only)': make_ctx2d(6, 1),
        'w 2/1/0.5 nb12': make_ctx(),
        'w 1/1/0.5 nb12': make_ctx(1.0),
        'w 2/1/0 nb16': make_ctx(2.0, 1.0, 0.0, 2.0, 16),
    }
    for name, fn in variants.items():
        c = simulate(data, fn, 0)
        print(f"  {name}: {c/8:.0f} B  {100*(c/base-1):+.2f} %")
