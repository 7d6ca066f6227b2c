"""cia402.Replay and Drive.replay: the replay interface, the same JSON as `cia402 replay`."""
import subprocess

import pytest

import cia402

EVENTS = """\
cw 0x06
cw 0x0F
# a comment line, then a blank one

set 0x605A 6
cw 0x02
cw 0x0F
fault 0x2310
cw 0x80
clear
cw 0x00
cw 0x80
sto on
sto off
voltage off
moving
standstill
link lost
link ok
local enable
remote off
set 0x605A 99
jump
cw 0x1FFFF
"""


def cli_lines(tool, events, *args):
    run = subprocess.run([tool, "replay", *args], input=events, capture_output=True, text=True, check=True)
    return run.stdout.splitlines()


@pytest.mark.parametrize("profile", cia402.profiles())
def test_every_line_is_the_one_the_command_line_prints(tool, profile):
    r = cia402.Replay(profile)
    ours = [r.feed_text(line) for line in EVENTS.splitlines()]
    ours = [line for line in ours if line]
    expected = cli_lines(tool, EVENTS, "--profile", profile)
    assert expected[1:] == ours
    assert cia402.Replay(profile).power_up == __import__("json").loads(expected[0])


def test_drive_replay_takes_the_drives_option_codes_as_set(tool):
    d = cia402.Drive()
    d[0x605A] = 6
    d[0x605E] = 0
    got = d.replay(EVENTS)
    expected = cli_lines(tool, EVENTS, "--set", "0x605A=6", "--set", "0x605E=0")
    assert got == [__import__("json").loads(line) for line in expected]


def test_a_profile_file_replays_as_the_command_line_does(tool, examples):
    path = str(examples / "profiles" / "custom-drive.toml")
    got = cia402.Drive.from_file(path).replay(EVENTS.splitlines())
    expected = cli_lines(tool, EVENTS, "--profile-file", path)
    assert got == [__import__("json").loads(line) for line in expected]


def test_power_up_then_enable():
    r = cia402.Replay()
    assert r.power_up == {"state": "SWITCH_ON_DISABLED", "statusword": "0x0250", "transitions": [0, 1],
                          "torque": False, "brake": "engaged", "ramp": "none", "error_code": "0x0000"}
    assert r.feed("cw 0x06")["transitions"] == [2]
    line = r.feed("cw 0x0F")
    assert (line["state"], line["statusword"], line["transitions"]) == ("OPERATION_ENABLED", "0x0237", [3, 4])
    assert r.feed("   # nothing") is None and r.feed("") is None
    assert r.line_number == 4 and r.state == "OPERATION_ENABLED" and r.control_word == 0x0F


def test_a_bad_line_answers_an_error_with_its_number_and_changes_nothing():
    r = cia402.Replay()
    r.feed("cw 0x06")
    assert r.feed("cw banana") == {"error": "cw value 'banana' is not a number", "line": 2}
    assert r.state == "READY_TO_SWITCH_ON" and r.control_word == 0x06


def test_run_returns_the_objects_of_the_non_blank_lines():
    lines = cia402.Replay().run("cw 0x06\n\n# x\ncw 0x0F\n")
    assert [line["state"] for line in lines] == ["READY_TO_SWITCH_ON", "OPERATION_ENABLED"]


def test_options_are_written_before_power_up_and_a_refused_one_raises():
    r = cia402.Replay(options={0x605A: 6})
    r.feed("cw 0x06")
    r.feed("cw 0x0F")
    assert r.feed("cw 0x02")["state"] == "QUICK_STOP_ACTIVE"
    with pytest.raises(cia402.SdoError) as refused:
        cia402.Replay(options={0x605A: 9})
    assert refused.value.code == 0x06090030


def test_feed_takes_one_line():
    with pytest.raises(cia402.ArgumentError):
        cia402.Replay().feed("cw 0x06\ncw 0x0F")
    with pytest.raises(cia402.ArgumentError):
        cia402.Replay().run(["cw 0x06", 6])
