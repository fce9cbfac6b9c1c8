-- capsim campaign database, schema version 6: which parts of each answer's error had no data.
-- An error is the largest of its mesh, periods and dt parts (campaign/analysis/uncertainty.h); a part without
-- data (one mesh level, no dt check, periods not recorded) is left out, so the error is then a lower bound.
-- Until now only error_note said so, and `capsim query table1` printed such an error like a complete one.
-- Each column lists the missing parts, comma-separated in the order mesh, periods, dt (e.g. 'mesh,dt'); NULL when
-- all three entered or the answer has no error. Rows of version 5 read as NULL until the campaign is analysed
-- again (`capsim campaign analyse --db DB`).

PRAGMA user_version = 6;

ALTER TABLE transitions ADD COLUMN ca_star_low_err_lacks TEXT;
ALTER TABLE transitions ADD COLUMN ca_star_high_err_lacks TEXT;
ALTER TABLE transitions ADD COLUMN ca_h_err_lacks TEXT;
