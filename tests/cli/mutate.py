# SPDX-License-Identifier: Apache-2.0
"""mutate.py SOURCE OUTDIR COUNT SEED: COUNT damaged copies of SOURCE, the same ones for the
same seed: flipped bits, truncations, zeroed or random ranges, duplicated chunks, and
numbers near the start (headers, counts, indices) replaced by extreme ones."""
import os
import random
import re
import sys

EXTREMES = [b"0", b"-1", b"2147483647", b"4294967295", b"99999999999", b"-2147483648",
            b"1e308", b"nan", b"inf"]


def mutate(data, rng):
    b = bytearray(data)
    kind = rng.randrange(6)
    if kind == 0:  # flipped bits
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(len(b))
            b[i] ^= 1 << rng.randrange(8)
    elif kind == 1:  # truncated
        b = b[:rng.randrange(len(b))]
    elif kind == 2:  # a zeroed range
        i, n = rng.randrange(len(b)), rng.randint(1, 64)
        b[i:i + n] = bytes(min(n, len(b) - i))
    elif kind == 3:  # a range of random bytes
        i, n = rng.randrange(len(b)), rng.randint(1, 32)
        b[i:i + n] = bytes(rng.randrange(256) for _ in range(min(n, len(b) - i)))
    elif kind == 4:  # a number near the start replaced by an extreme one
        numbers = list(re.finditer(rb"-?\d+", bytes(b[:1000])))
        if numbers:
            m = rng.choice(numbers)
            b = b[:m.start()] + rng.choice(EXTREMES) + b[m.end():]
    else:  # a chunk duplicated
        i, n = rng.randrange(len(b)), rng.randint(1, 256)
        b[i:i] = b[i:i + n]
    return bytes(b)


def main():
    source, out, count, seed = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    data = open(source, "rb").read()
    stem, ext = os.path.splitext(os.path.basename(source))
    rng = random.Random(seed)
    os.makedirs(out, exist_ok=True)
    for k in range(count):
        with open(os.path.join(out, "%s_%03d%s" % (stem, k, ext)), "wb") as f:
            f.write(mutate(data, rng))


main()
