"""A lecturer's tools for a class graded with nbgrader: parallel autograde and the class report.

The console command ``geomlib-course`` (installed with geomlib; its packages come with the
``course`` extra: nbgrader, copydetect and a PostgreSQL driver):

* ``geomlib-course autograde COURSE_DIR ASSIGNMENT --workers N`` runs nbgrader's own
  ``autograde`` for every submitted student, N at once, with a progress line per student
  (:mod:`.autograde`), leaving in the course's gradebook exactly the grades a serial
  ``nbgrader autograde`` leaves (:mod:`.gradebook`);
* ``geomlib-course report COURSE_DIR ASSIGNMENT`` writes the class report: per exercise the
  pass rate, the named mistakes ranked, the catch-alls, the discussion answers waiting for a
  grader, and the submissions that look copied (:mod:`.report`, :mod:`.similarity`).

This layer sits above ``teaching``: it may import any layer of geomlib; no module of geomlib
and no notebook imports it.
"""
