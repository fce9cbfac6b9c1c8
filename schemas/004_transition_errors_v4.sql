-- capsim campaign database, schema version 4: the numerical uncertainty of every answer.
-- Each transition row says what its group is for in its cell (role) and carries the error of each answer in
-- Ca, the part that dominates it and how it was obtained (campaign/analysis/uncertainty.h). Columns are
-- added in place: rows of version 3 read as role 'answer' without errors until the campaign is analysed again.

PRAGMA user_version = 4;

ALTER TABLE transitions ADD COLUMN role TEXT NOT NULL DEFAULT 'answer'
  CHECK (role IN ('answer', 'scan', 'mesh_check', 'dt_check'));
ALTER TABLE transitions ADD COLUMN ca_star_low_err REAL;          -- error of ca_star_low in Ca
ALTER TABLE transitions ADD COLUMN ca_star_high_err REAL;         -- error of ca_star_high in Ca
ALTER TABLE transitions ADD COLUMN ca_h_err REAL;                 -- error of ca_h in Ca
ALTER TABLE transitions ADD COLUMN ca_star_low_err_source TEXT;   -- mesh | periods | dt | bracket
ALTER TABLE transitions ADD COLUMN ca_star_high_err_source TEXT;
ALTER TABLE transitions ADD COLUMN ca_h_err_source TEXT;
ALTER TABLE transitions ADD COLUMN error_levels TEXT;             -- mesh levels used, e.g. '2,3'
ALTER TABLE transitions ADD COLUMN error_note TEXT NOT NULL DEFAULT '';  -- every part and how it was obtained
