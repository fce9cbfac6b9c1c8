-- capsim campaign database, schema version 5: each answer's value on the other levels its mesh error compared
-- (the error check: a check level's value against the coarser answer ± its error). Until now that
-- value was only in the error_note text, and `scripts/table1 --error-check` read it back from there.
-- level_answers is a JSON object {"ca_h": {"2": 0.2312, "4": 0.6031}, "ca_star_low": {...}, ...} (level -> value
-- in Ca, full precision; campaign/analysis/uncertainty.h AnswerError::on_level). Rows of version 4 read as
-- NULL until the campaign is analysed again (`capsim campaign analyse --db DB`).

PRAGMA user_version = 5;

ALTER TABLE transitions ADD COLUMN level_answers TEXT;  -- JSON: answer -> {level: value}
