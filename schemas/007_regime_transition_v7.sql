-- capsim campaign database, schema version 7: the tumbling-to-swinging transition read from the cases' regimes.
-- The seed's Ca* (min D12 < 0.05) marks the transition only where a tumbling capsule does not pass through a
-- round profile: with a viscous interior (λ ≥ 5) it does, and Ca* is then found where every case tumbles.
-- ca_ts_low and ca_ts_high are the adjacent sampled Ca between which the reported regime changes from tumbling
-- (below) to swinging (above), both set or both NULL; ca_ts_note says why there is none, that the sampled regimes
-- are not monotone, or which samples (neither tumbling nor swinging) were skipped (campaign/analysis/transitions.h,
-- analyse_group). Rows of version 6 read as NULL until the campaign is analysed again
-- (`capsim campaign analyse --db DB`).

PRAGMA user_version = 7;

ALTER TABLE transitions ADD COLUMN ca_ts_low REAL;   -- largest sampled Ca of the bracket's tumbling side
ALTER TABLE transitions ADD COLUMN ca_ts_high REAL;  -- smallest sampled Ca of the bracket's swinging side
ALTER TABLE transitions ADD COLUMN ca_ts_note TEXT;  -- NULL: a clean bracket, a sphere, or not analysed yet
