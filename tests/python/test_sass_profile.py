"""tools/sass_profile.py on a small CSV of the form ncu's SASS source page takes (a kernel
row, a header row, one row per SASS instruction), and on the committed profile."""
import os
from pathlib import Path

import pytest

import sass_profile

ROOT = Path(__file__).resolve().parents[2]
HEADER = ['"Address"', '"Source"', f'"{sass_profile.STALL_COLUMN}"', '"Instructions Executed"',
          '"Thread Instructions Executed"']


def write_csv(path, rows):
    lines = ['"Kernel Name","k_test(int)"', ",".join(HEADER)]
    lines += [",".join(f'"{c}"' for c in r) for r in rows]
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture
def profile(tmp_path):
    rows = [  # address, source, stalls, executed, thread-executed
        ("0x0", "LDC R1, c[0x0][0x28]", 1, 10, 320),
        ("0x10", "FSETP.GT.AND P0, PT, R2, R3, PT", 5, 100, 3200),
        ("0x20", "FSEL R2, R2, R3, P0", 3, 100, 3200),
        ("0x30", "@!P0  BRA 0x10", 2, 100, 3000),
        ("0x40", "FMNMX R4, R2, R3, PT", 0, 40, 1280),
        ("0x50", "EXIT", 0, 10, 320),
    ]
    p = tmp_path / "k-sass.csv"
    write_csv(p, rows)
    return p


def test_reads_every_instruction_in_order(profile):
    ins = sass_profile.read_instructions(profile)
    assert [i.executed for i in ins] == [10, 100, 100, 100, 40, 10]
    assert ins[3].text == "@!P0  BRA 0x10" and ins[1].stalls == 5


def test_opcodes_drop_the_predicate_guard():
    assert sass_profile.opcode("@!P0  BRA 0x10") == "BRA"
    assert sass_profile.opcode("@UP1 IADD3 R1, R2, R3, RZ") == "IADD3"
    assert sass_profile.opcode("FSETP.GEU.AND P0, PT, R1, R2, PT") == "FSETP.GEU.AND"


def test_by_opcode_and_hot_blocks(profile):
    ins = sass_profile.read_instructions(profile)
    ops = sass_profile.by_opcode(ins)
    assert ops["FSEL"] == (100, 3) and ops["FMNMX"] == (40, 0)
    assert sum(n for n, _ in ops.values()) == 360
    blocks = sass_profile.hot_blocks(ins)
    assert (blocks[0].start, blocks[0].end, blocks[0].instructions, blocks[0].stalls) == (1, 3, 300, 10)
    # one execution count but not adjacent: two blocks
    assert sorted((b.start, b.end) for b in blocks if b.executed == 10) == [(0, 0), (5, 5)]


def test_report_per_unit(profile):
    text = sass_profile.report(sass_profile.read_instructions(profile), per=10, top=3)
    assert "36.0 executed warp instructions per unit (360 in all), 11 stall samples" in text
    assert "FSETP.GT.AND" in text and "FMNMX" not in text.split("block")[0]  # top 3 opcodes only
    assert "    1-    3    3     10.000  83.3%" in text


def test_refuses_what_is_not_a_source_page(tmp_path, capsys):
    p = tmp_path / "details.csv"
    p.write_text('"ID","Metric Name","Metric Value"\n"0","Duration","28.6"\n')
    assert sass_profile.main([str(p)]) == 2
    assert "not the CSV of ncu --page source" in capsys.readouterr().err
    assert sass_profile.main([str(tmp_path / "missing.csv")]) == 2
    bad = tmp_path / "bad.csv"
    bad.write_text(",".join(HEADER) + '\n"0x0","NOP","x","1","32"\n')
    assert sass_profile.main([str(bad)]) == 2
    assert "not a number" in capsys.readouterr().err


def test_refuses_special_files_without_reading_them(tmp_path, capsys):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)  # no writer: opening it would wait for ever
    for p in (fifo, Path("/dev/zero"), tmp_path):
        assert sass_profile.main([str(p)]) == 2
        assert "not a regular file" in capsys.readouterr().err


def test_stalls_by_reason_and_instruction(tmp_path, capsys):
    # ncu's per-reason columns, each with a "(Not Issued)" twin that is not counted again
    header = HEADER + ['"stall_long_sb"', '"stall_wait"', '"stall_long_sb (Not Issued)"']
    rows = [("0x0", "LDG.E R3, desc[UR4][R2.64]", 2, 100, 3200, 0, 2, 0),
            ("0x10", "ISETP.NE.AND P0, PT, R3, -0x1, PT", 60, 100, 3200, 58, 2, 58),
            ("0x20", "ATOMG.E.ADD.64 PT, R8, desc[UR4][R2.64], R6", 0, 100, 100, 0, 0, 0),
            ("0x30", "SHFL.IDX PT, R9, R8, RZ, 0x1f", 38, 100, 3200, 30, 8, 30)]
    p = tmp_path / "stalls-sass.csv"
    p.write_text("\n".join(['"Kernel Name","k_test(int)"', ",".join(header)] +
                           [",".join(f'"{c}"' for c in r) for r in rows]) + "\n")
    ins = sass_profile.read_instructions(p)
    assert ins[1].reasons == {"long_sb": 58, "wait": 2} and ins[2].reasons == {}
    text = sass_profile.stall_report(ins, top=2)
    assert "100 stall samples; by reason: long_sb 88.0 %, wait 12.0 %" in text
    body = text.splitlines()[3:]
    assert len(body) == 2  # the two most stalled, in address order
    assert body[0].split()[:3] == ["1", "60.0", "100"] and body[0].endswith("long_sb 58, wait 2")
    assert body[1].split()[:3] == ["3", "38.0", "100"] and "SHFL.IDX" in body[1]
    assert sass_profile.main([str(p), "--stalls", "1"]) == 0
    assert "ISETP.NE.AND" in capsys.readouterr().out.split("by reason")[1]


def test_stalls_without_samples_are_an_error(profile, tmp_path, capsys):
    p = tmp_path / "nostall-sass.csv"
    write_csv(p, [("0x0", "NOP", 0, 10, 320)])
    assert sass_profile.main([str(p), "--stalls", "3"]) == 2
    assert "no stall samples" in capsys.readouterr().err


def test_refuses_bad_options(profile):
    for args in (["--per", "0"], ["--per", "nan"], ["--top", "0"], ["--stalls", "-1"]):
        with pytest.raises(SystemExit) as e:
            sass_profile.main([str(profile), *args])
        assert e.value.code == 2


def test_gzipped_profile_of_record():
    p = ROOT / "results/nvidia-h200/archive/sass-profile-97ba504/pixel-sass.csv.gz"
    ins = sass_profile.read_instructions(p)
    assert len(ins) == 3672
    total = sum(i.executed for i in ins)
    assert total == 10478589  # ncu's Executed Instructions for that launch
    ops = sass_profile.by_opcode(ins)
    # what the slab test's ternary min/max compiled to: FSETP + FSEL pairs, few FMNMX
    assert ops["FSEL"][0] / total > 0.10 and ops["FMNMX"][0] / total < 0.02
