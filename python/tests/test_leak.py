"""No memory leak over 1000 encode/decode calls (and the other entry points): RSS stays flat."""

import os
import unittest

import numpy as np

import dmc
import support

PAGE_SIZE = os.sysconf("SC_PAGE_SIZE")


def resident_bytes():
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * PAGE_SIZE


@unittest.skipUnless(os.path.exists("/proc/self/statm"), "needs /proc (Linux)")
class LeakTest(unittest.TestCase):
    def assert_flat(self, call, repetitions, leak_per_call):
        """Runs `call` 100 times to settle the allocator, then `repetitions` times, and asserts
        the resident set grew by less than a third of what leaking `leak_per_call` bytes on every
        call would add."""
        for _ in range(100):
            call()
        before = resident_bytes()
        for _ in range(repetitions):
            call()
        growth = resident_bytes() - before
        self.assertLess(growth, repetitions * leak_per_call / 3,
                        f"RSS grew by {growth / 1e6:.1f} MB over {repetitions} calls")

    def test_encode_decode_1000_times(self):
        frames, faces = support.small_animation(frames=2, resolution=150)
        decoded_bytes = frames.nbytes + faces.nbytes  # what a leaked decode result would hold

        def round_trip():
            frames_out, faces_out = dmc.decode(dmc.encode(frames, faces, operator="tutte"))
            assert frames_out.shape == frames.shape and faces_out.shape == faces.shape

        self.assert_flat(round_trip, 1000, decoded_bytes)

    def test_errors_laplacians_and_metrics_do_not_leak(self):
        frames, faces = support.small_animation(frames=2, resolution=1000)
        bad_faces = faces.copy()
        bad_faces[0, 0] = frames.shape[1]

        def calls():
            matrix = dmc.laplacian(frames, faces, "cotan")
            assert matrix.nnz > 0
            dmc.metrics(frames, frames, faces)
            try:
                dmc.encode(frames, bad_faces)
            except dmc.Error:
                pass
            else:
                raise AssertionError("invalid faces accepted")

        # A leaked CSR matrix alone holds 12 bytes per stored entry.
        self.assert_flat(calls, 300, 12 * 7 * frames.shape[1])


if __name__ == "__main__":
    unittest.main()
