"""LMS exports: each file against its system's documented import header and conventions.

The headers asserted here are the documented ones: Canvas's gradebook import ("Student,
ID, SIS User ID, SIS Login ID, Section", then the assignments, and an optional "Points
Possible" row); Moodle's CSV grade import (user columns, then one column per grade item,
mapped by e-mail address or ID number); Brightspace's grades import ("OrgDefinedId",
"Username", "<item> Points Grade" columns and the "End-of-Line Indicator" column of "#").
"""

import csv

import pytest

from course_lib.instructor.__main__ import main
from course_lib.instructor.lms import export_grades, read_gradebook
from course_lib.instructor.roster import read_roster
from course_lib.instructor.verdicts import FIELDS

A, B = "02_forward_euler", "05_newtons_second_law"


def gradebook(path, scores):
    """A grader gradebook: ``scores[student][assignment]`` = list of (points, possible)."""
    with path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=FIELDS)
        writer.writeheader()
        for student, by_assignment in scores.items():
            for assignment, exercises in by_assignment.items():
                for i, (points, possible) in enumerate(exercises):
                    writer.writerow({"student": student, "assignment": assignment, "exercise": f"e{i}",
                                     "status": "correct" if points else "incorrect", "points": points,
                                     "possible": possible, "passed": 0, "total": 0, "message": "m",
                                     "file": ""})
    return path


ROSTER = """Student,First Name,Last Name,Email,SIS_ID,Username,Canvas ID,Section
amy,Amy,O'Neil,amy@uni.example,007123,amy.oneil,101,A
ben,Ben,"Smith, Jr.",ben@uni.example,000456,bsmith,102,B
cy,Cy,Zhou,cy@uni.example,000789,czhou,103,A
"""


@pytest.fixture
def files(tmp_path):
    book = gradebook(tmp_path / "grades.csv", {
        "amy": {A: [(1, 1), (2, 2)], B: [(0, 1), (1, 1)]},
        "ben": {A: [(0, 1), (0, 2)], B: [(1, 1), (1, 1)]},
    })
    (tmp_path / "roster.csv").write_text(ROSTER)
    return book, tmp_path / "roster.csv"


def rows_of(path):
    with path.open(newline="", encoding="utf-8") as fh:
        return list(csv.reader(fh))


def test_gradebook_totals_per_assignment(files):
    assignments, totals = read_gradebook(files[0])
    assert assignments == [A, B]
    assert totals["amy"] == {A: (3, 3), B: (1, 2)} and totals["ben"] == {A: (0, 3), B: (2, 2)}


def test_canvas_file(files, tmp_path):
    done = export_grades(*files, "canvas", tmp_path / "canvas.csv", items={A: "Notebook 02 (1234)"})
    table = rows_of(done["path"])
    assert table[0] == ["Student", "ID", "SIS User ID", "SIS Login ID", "Section", "Notebook 02 (1234)", B]
    assert table[1] == ["    Points Possible", "", "", "", "", "3", "2"]
    assert table[2] == ["O'Neil, Amy", "101", "007123", "amy.oneil", "A", "3", "1"]
    assert table[3] == ["Smith, Jr., Ben", "102", "000456", "bsmith", "B", "0", "2"]
    assert done["not_graded"] == ["cy"] and len(table) == 4


def test_moodle_file(files, tmp_path):
    table = rows_of(export_grades(*files, "moodle", tmp_path / "moodle.csv")["path"])
    assert table[0] == ["First name", "Last name", "ID number", "Email address", A, B]
    assert table[1:] == [["Amy", "O'Neil", "007123", "amy@uni.example", "3", "1"],
                         ["Ben", "Smith, Jr.", "000456", "ben@uni.example", "0", "2"]]


def test_brightspace_file(files, tmp_path):
    path = export_grades(*files, "brightspace", tmp_path / "d2l.csv", items={B: "Newton"})["path"]
    table = rows_of(path)
    assert table[0] == ["OrgDefinedId", "Username", f"{A} Points Grade", "Newton Points Grade",
                        "End-of-Line Indicator"]
    assert table[1] == ["#007123", "#amy.oneil", "3", "1", "#"]  # '#' keeps the leading zeros
    assert table[2] == ["#000456", "#bsmith", "0", "2", "#"]
    assert path.read_bytes().count(b"\r\n") == 3  # CSV lines as Python's csv writes them


def test_a_student_missing_from_the_roster_stops_the_export_and_is_named(files, tmp_path):
    book, roster = files
    roster.write_text("\n".join(ROSTER.splitlines()[:2]) + "\n")  # ben is not in it
    for fmt in ("canvas", "moodle", "brightspace"):
        with pytest.raises(ValueError, match="match no roster entry: ben"):
            export_grades(book, roster, fmt, tmp_path / f"{fmt}.csv")
        assert not (tmp_path / f"{fmt}.csv").exists()


def test_a_student_without_the_formats_identifier_is_named(files, tmp_path):
    book, roster = files
    roster.write_text("student,first_name,last_name,email\namy,Amy,O,\nben,Ben,S,ben@x\n")
    with pytest.raises(ValueError, match=r"email or sis_id.*amy"):
        export_grades(book, roster, "moodle", tmp_path / "m.csv")
    with pytest.raises(ValueError, match=r"sis_id or username.*amy, ben"):
        export_grades(book, roster, "brightspace", tmp_path / "b.csv")


@pytest.mark.parametrize("text,message", [
    ("name,email\nAmy,a@x\n", "no 'student' column"),
    ("student,email\namy,a@x\namy,b@x\n", "line 3: 'amy' appears twice"),
    ("student,email\n,a@x\n", "line 2: the 'student' column is empty"),
    ("", "is empty"),
])
def test_bad_rosters_say_what_is_wrong(tmp_path, text, message):
    (tmp_path / "r.csv").write_text(text)
    with pytest.raises(ValueError, match=message):
        read_roster(tmp_path / "r.csv")


def test_roster_keyed_by_another_column_and_lms_headers_as_aliases(tmp_path):
    (tmp_path / "r.csv").write_text("OrgDefinedId,Username,Email Address\n0042,amy.o,amy@x\n")
    people = read_roster(tmp_path / "r.csv", key="username")
    assert people["amy.o"].get("sis_id") == "0042" and people["amy.o"].get("email") == "amy@x"
    with pytest.raises(ValueError, match="valid choices"):
        read_roster(tmp_path / "r.csv", key="shoe_size")


def test_bad_requests_are_refused(files, tmp_path):
    with pytest.raises(ValueError, match="valid choices"):
        export_grades(*files, "blackboard", tmp_path / "x.csv")
    with pytest.raises(ValueError, match="not assignments of the gradebook"):
        export_grades(*files, "canvas", tmp_path / "x.csv", items={"99_nothing": "X"})
    (tmp_path / "bad.csv").write_text("a,b\n1,2\n")
    with pytest.raises(ValueError, match="not a gradebook"):
        export_grades(tmp_path / "bad.csv", files[1], "canvas", tmp_path / "x.csv")


def test_command_line(files, tmp_path, capsys):
    book, roster = files
    assert main(["export", "brightspace", str(book), "--roster", str(roster), "--item", f"{A}=NB 02"]) == 0
    assert rows_of(tmp_path / "grades-brightspace.csv")[0][2] == "NB 02 Points Grade"
    assert "1 roster entries have no graded submission" in capsys.readouterr().err
    roster.write_text("student\namy\n")
    assert main(["export", "canvas", str(book), "--roster", str(roster)]) == 2
    assert "ben" in capsys.readouterr().err
