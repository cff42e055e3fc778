"""lucent.tea, tea_statistics and noise: `lucent tea` and `lucent noise` as calls, with the
CLI's numbers (the block it prints, the statistics table's rows, the PFM image it writes)."""
import subprocess

import numpy as np
import pytest

import lucent
from test_samples import read_pfm


def test_tea_is_the_cipher_and_the_clis_block(cli):
    assert lucent.tea((0, 0), (0, 0, 0, 0)) == (0x41EA3A0A, 0x94BAA940)  # TEA's test vector
    assert lucent.tea(np.zeros(2, np.uint32), np.zeros(4, np.int64)) == (0x41EA3A0A, 0x94BAA940)
    mine = lucent.tea((0x12345678, 7), [1, 2, 3, 4], rounds=4)
    run = subprocess.run([cli, "tea", "--block", "0x12345678,7", "--key", "1,2,3,4", "--rounds", "4"],
                         capture_output=True, text=True, check=True)
    assert run.stdout.split() == [f"{w:08x}" for w in mine]


def test_statistics_fail_few_rounds_and_pass_the_cipher(cli):
    rows = lucent.tea_statistics(rounds=[1, 32], blocks=20000)
    assert [r["rounds"] for r in rows] == [1, 32]
    assert rows[0]["passes"] is False and rows[1]["passes"] is True
    assert rows[1]["bytes"] == 8 * 20000
    assert abs(rows[1]["ones_fraction"] - 0.5) < 0.01
    run = subprocess.run([cli, "tea", "--statistics", "--blocks", "20000"], capture_output=True, text=True,
                         check=True)
    table = {int(line.split()[0]): line.split() for line in run.stdout.splitlines()[1:]}
    assert float(table[32][1]) == pytest.approx(rows[1]["ones_fraction"], abs=1e-5)
    assert table[1][-1] == "FAIL" and table[32][-1] == "pass"


@pytest.mark.parametrize("kind, size", [("white", 16), ("gradient", 40), ("spectrum", 64)])
def test_noise_is_the_image_the_cli_writes(tmp_path, cli, kind, size):
    mine = lucent.noise(kind, size=size, rounds=4, seed=5, device=2)
    assert mine.shape == (size, size) and mine.dtype == np.float32
    out = tmp_path / "noise.pfm"
    subprocess.run([cli, "noise", "--kind", kind, "--size", str(size), "--rounds", "4", "--seed", "5",
                    "--device", "2", "--out", str(out)], capture_output=True, check=True)
    theirs = read_pfm(out)
    np.testing.assert_array_equal(mine, theirs[:, :, 0])
    assert 0.0 <= mine.min() and mine.max() <= 1.0
    assert not np.array_equal(mine, lucent.noise(kind, size=size, rounds=4))  # the fixed key


def test_default_sizes_are_the_clis():
    assert lucent.noise("white").shape == (64, 64)
    assert lucent.noise("gradient", rounds=2).shape == (256, 256)


@pytest.mark.parametrize("call, error, words", [
    (lambda: lucent.tea((0, 0), (0, 0, 0, 0), rounds=0), ValueError, "tea: rounds must be 1..64"),
    (lambda: lucent.tea((0,), (0, 0, 0, 0)), ValueError, "tea: block must be 2 integers"),
    (lambda: lucent.tea((0, -1), (0, 0, 0, 0)), ValueError, "tea: block must be 2 integers in [0, 2**32)"),
    (lambda: lucent.tea((0, 0), (0, 0, 0, 2**32)), ValueError, "tea: key must be 4 integers"),
    (lambda: lucent.tea((0, 0), "0,0,0,0"), ValueError, "tea: key must be 4 integers"),
    (lambda: lucent.tea((0, 2**70), (0, 0, 0, 0)), ValueError, "tea: block must be 2 integers"),
    (lambda: lucent.tea((0, 1.0), (0, 0, 0, 0)), ValueError, "tea: block must be 2 integers"),
    (lambda: lucent.tea_statistics(blocks=10), ValueError, "tea_statistics: blocks must be 1000..2**26"),
    (lambda: lucent.tea_statistics(rounds=[65]), ValueError, "tea_statistics: rounds must be 1..64"),
    (lambda: lucent.noise("pink"), ValueError, "noise: kind is 'pink'"),
    (lambda: lucent.noise("white", size=4), ValueError, "noise: size must be 8..4096"),
    (lambda: lucent.noise("white", seed=2**32), ValueError, "noise: seed must be in [0, 2**32)"),
])
def test_bad_arguments_name_the_argument(call, error, words):
    with pytest.raises(error) as e:
        call()
    assert words in str(e.value)
