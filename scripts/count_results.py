#!/usr/bin/env python3
"""Counts test cases in catkin's JUnit result files and prints "N passed, N failed".

usage: count_results.py RESULTS_DIR RUN_STATUS

A test case fails when it has a <failure> or <error>. A missing result file (catkin writes
MISSING-*.xml when a test produced none, e.g. it crashed) counts as a failure, and so does a
nonzero RUN_STATUS with no failing case to show for it. rostest writes both the test node's own
gtest cases (rosunit-*.xml) and a summary case per .test file (rostest-*.xml) that only says
whether the node's result file came back: the summary is counted only when it failed.
Exits 1 when anything failed or nothing ran.
"""
import pathlib
import sys
import xml.etree.ElementTree as ElementTree


def main():
    results, run_status = pathlib.Path(sys.argv[1]), int(sys.argv[2])
    passed = failed = 0
    for path in sorted(results.rglob("*.xml")):
        try:
            root = ElementTree.parse(path).getroot()
        except ElementTree.ParseError as error:
            print(f"FAILED: unreadable result file {path}: {error}")
            failed += 1
            continue
        summary = path.name.startswith("rostest-")
        for case in root.iter("testcase"):
            name = f"{path.stem}: {case.get('classname', '')}.{case.get('name', '')}"
            problem = case.find("failure") if case.find("failure") is not None else case.find("error")
            if problem is not None:
                print(f"FAILED: {name}")
                detail = (problem.get("message") or "") + "\n" + (problem.text or "")
                for line in detail.strip().splitlines()[:12]:
                    print(f"    {line}")
                failed += 1
            elif case.find("skipped") is not None or summary:
                continue
            else:
                passed += 1
    if run_status != 0 and failed == 0:
        failed = 1
    if passed + failed == 0:
        print("no test results found in", results)
        failed = 1
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
