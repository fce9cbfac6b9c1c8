-- capsim campaign database, schema version 2: Slurm job arrays (`capsim campaign submit|collect`).
-- Additive only (CREATE ... IF NOT EXISTS, no ALTER): a version-1 database opened for writing by a
-- version-2 capsim is migrated by applying the whole embedded DDL in one transaction (the version-1 part is
-- a no-op there); version-1 databases are read as they are. Array tasks never open this file: they write
-- DIR/result.json (the worker's JSON line) and DIR/slurm_exit.json in each case folder; `campaign collect`
-- ingests them here.

PRAGMA user_version = 2;

-- One row per `capsim campaign submit` that sbatch accepted.
CREATE TABLE IF NOT EXISTS slurm_jobs (
  job_id         TEXT PRIMARY KEY,          -- sbatch --parsable (without ";cluster")
  campaign_id    INTEGER NOT NULL REFERENCES campaigns(campaign_id),
  submitted_at   TEXT NOT NULL,
  script_path    TEXT NOT NULL,             -- the sbatch script as submitted (kept in RUNS/slurm/)
  n_tasks        INTEGER NOT NULL,          -- array size
  n_cases        INTEGER NOT NULL,
  cases_per_task INTEGER NOT NULL,
  array_limit    INTEGER,                   -- %K of --array, NULL: no limit
  partition      TEXT,
  time_limit     TEXT,
  threads        INTEGER NOT NULL,          -- --cpus-per-task and capsim run --threads
  state          TEXT NOT NULL DEFAULT 'submitted'
                 CHECK (state IN ('submitted', 'collected')),  -- collected: every case of it resolved
  collected_at   TEXT
);

-- Which array task owns which case (task_index = position / cases_per_task), and how collect resolved it.
CREATE TABLE IF NOT EXISTS slurm_tasks (
  job_id      TEXT NOT NULL REFERENCES slurm_jobs(job_id),
  task_index  INTEGER NOT NULL,             -- SLURM_ARRAY_TASK_ID
  position    INTEGER NOT NULL,             -- order of the case in the job's case list
  case_id     TEXT NOT NULL REFERENCES cases(case_id),
  resumed     INTEGER NOT NULL DEFAULT 0,   -- a checkpoint existed at submission (the task passes --resume)
  state       TEXT NOT NULL DEFAULT 'submitted'
              CHECK (state IN ('submitted', 'ingested', 'interrupted', 'failed', 'lost')),
  exit_code   INTEGER,                      -- from slurm_exit.json; NULL if the task never finished the case
  host        TEXT,
  wall_s      REAL,
  resolved_at TEXT,
  PRIMARY KEY (job_id, case_id)
);
CREATE INDEX IF NOT EXISTS slurm_tasks_open ON slurm_tasks(state, case_id);
