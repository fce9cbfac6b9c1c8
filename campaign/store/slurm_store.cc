#include "campaign/store/slurm_store.h"

#include "campaign/store/store.h"

namespace capsim::campaign {

namespace {
const char* kNow = "strftime('%Y-%m-%dT%H:%M:%fZ','now')";
template <class T>
SqlValue opt(const std::optional<T>& v) {
  if (!v) return nullptr;
  if constexpr (std::is_integral_v<T>) return std::int64_t{*v};
  else return *v;
}
SqlValue text_or_null(const std::string& s) { return s.empty() ? SqlValue{nullptr} : SqlValue{s}; }
}  // namespace

std::vector<std::string> open_job_ids(Db& db) {
  std::vector<std::string> ids;
  if (!has_table(db, "slurm_jobs")) return ids;
  Stmt s(db, "SELECT DISTINCT job_id FROM slurm_tasks WHERE state='submitted'");
  while (s.step()) ids.push_back(s.text(0));
  return ids;
}

std::set<std::int64_t> campaigns_of_case(Db& db, const std::string& case_id) {
  std::set<std::int64_t> out;
  Stmt s(db, "SELECT campaign_id FROM campaign_cases WHERE case_id=?");
  s.bind(1, case_id);
  while (s.step()) out.insert(s.integer(0));
  return out;
}

std::vector<UnfinishedCase> unfinished_cases(Db& db, std::optional<std::int64_t> campaign_id) {
  std::string q = "SELECT c.case_id, c.params_json, c.out_dir FROM cases c WHERE c.status IN ('queued','failed')";
  if (campaign_id) q += " AND c.case_id IN (SELECT case_id FROM campaign_cases WHERE campaign_id=?1)";
  Stmt s(db, q);
  if (campaign_id) s.bind(1, *campaign_id);
  std::vector<UnfinishedCase> out;
  while (s.step()) out.push_back({s.text(0), CaseParams::from_json(s.text(1)), s.text(2)});
  return out;
}

std::vector<SubmittedTask> submitted_tasks(Db& db, std::optional<std::int64_t> campaign_id) {
  std::vector<SubmittedTask> out;
  if (!has_table(db, "slurm_tasks")) return out;
  std::string q = "SELECT st.job_id, st.task_index, st.case_id, c.status, c.out_dir FROM slurm_tasks st "
                  "JOIN cases c ON c.case_id=st.case_id JOIN slurm_jobs j ON j.job_id=st.job_id "
                  "WHERE st.state='submitted'";
  if (campaign_id) q += " AND j.campaign_id=?1";
  q += " ORDER BY st.job_id, st.position";
  Stmt s(db, q);
  if (campaign_id) s.bind(1, *campaign_id);
  while (s.step()) out.push_back({s.text(0), static_cast<int>(s.integer(1)), s.text(2), s.text(3), s.text(4)});
  return out;
}

void add_collected_attempt(Db& db, const std::string& case_id, const std::optional<std::string>& host, bool resumed,
                           const std::string& outcome, std::optional<int> exit_code, const std::string& error) {
  Stmt a(db, std::string("INSERT INTO attempts(case_id,started_at,finished_at,host,worker_pid,resumed,outcome,exit_code,"
                         "error) VALUES(?,") + kNow + "," + kNow + ",?,NULL,?,?,?,?)");
  a.bind(1, case_id).bind(2, opt(host)).bind(3, std::int64_t{resumed});
  a.bind(4, outcome).bind(5, opt(exit_code)).bind(6, text_or_null(error));
  a.step();
}

void mark_collected_result(Db& db, const std::string& case_id, const std::string& status,
                           std::optional<double> task_wall_s, std::optional<double> result_wall_s,
                           const std::optional<std::string>& host, const std::optional<std::string>& code_version,
                           const std::string& error, const std::string& h5_path) {
  Stmt u(db, std::string("UPDATE cases SET status=?, resumable=0, finished_at=") + kNow +
                 ", wall_s=coalesce(?,?), exit_code=0, host=coalesce(?,host), code_version=coalesce(?,code_version), "
                 "error=?, h5_path=?, attempts=attempts+1 WHERE case_id=?");
  u.bind(1, status).bind(2, opt(task_wall_s)).bind(3, opt(result_wall_s)).bind(4, opt(host));
  u.bind(5, opt(code_version)).bind(6, text_or_null(error)).bind(7, text_or_null(h5_path)).bind(8, case_id);
  u.step();
}

void mark_collected_failure(Db& db, const std::string& case_id, const std::string& status, bool resumable,
                            const std::string& error, std::optional<int> exit_code,
                            const std::optional<std::string>& host, bool attempted) {
  Stmt u(db, std::string("UPDATE cases SET status=?, resumable=?, error=?, exit_code=?, host=coalesce(?,host), "
                         "finished_at=") + kNow + ", attempts=attempts+? WHERE case_id=?");
  u.bind(1, status).bind(2, std::int64_t{resumable}).bind(3, error).bind(4, opt(exit_code)).bind(5, opt(host));
  u.bind(6, std::int64_t{attempted ? 1 : 0}).bind(7, case_id);
  u.step();
}

void resolve_task(Db& db, const std::string& job_id, const std::string& case_id, const std::string& state,
                  std::optional<int> exit_code, const std::optional<std::string>& host, std::optional<double> wall_s) {
  Stmt st(db, std::string("UPDATE slurm_tasks SET state=?, exit_code=?, host=?, wall_s=?, resolved_at=") + kNow +
                  " WHERE case_id=?5 AND (?6 = '' AND state='submitted' OR job_id=?6)");
  st.bind(1, state).bind(2, opt(exit_code)).bind(3, opt(host)).bind(4, opt(wall_s)).bind(5, case_id).bind(6, job_id);
  st.step();
}

void close_collected_jobs(Db& db) {
  db.exec(std::string("UPDATE slurm_jobs SET state='collected', collected_at=") + kNow +
          " WHERE state='submitted' AND NOT EXISTS (SELECT 1 FROM slurm_tasks t WHERE t.job_id=slurm_jobs.job_id "
          "AND t.state='submitted')");
}

std::pair<std::int64_t, std::string> open_tasks_of_campaign(Db& db, std::int64_t campaign_id) {
  if (!has_table(db, "slurm_tasks")) return {0, ""};
  Stmt s(db, "SELECT count(*), group_concat(DISTINCT t.job_id) FROM slurm_tasks t JOIN campaign_cases cc ON "
             "cc.case_id=t.case_id WHERE t.state='submitted' AND cc.campaign_id=?");
  s.bind(1, campaign_id);
  if (!s.step()) return {0, ""};
  return {s.integer(0), s.text(1)};
}

void record_slurm_job(Db& db, const SlurmJobRecord& job) {
  Transaction t(db);
  Stmt j(db, std::string("INSERT INTO slurm_jobs(job_id,campaign_id,submitted_at,script_path,n_tasks,n_cases,"
                         "cases_per_task,array_limit,partition,time_limit,threads) VALUES(?,?,") + kNow +
                 ",?,?,?,?,?,?,?,?)");
  j.bind(1, job.job_id).bind(2, job.campaign_id).bind(3, job.script_path).bind(4, std::int64_t{job.n_tasks});
  j.bind(5, std::int64_t(job.case_ids.size())).bind(6, std::int64_t{job.cases_per_task});
  j.bind(7, job.array_limit > 0 ? SqlValue{std::int64_t{job.array_limit}} : SqlValue{nullptr});
  j.bind(8, text_or_null(job.partition)).bind(9, text_or_null(job.time_limit)).bind(10, std::int64_t{job.threads});
  j.step();
  Stmt c(db, "INSERT INTO slurm_tasks(job_id,task_index,position,case_id,resumed) VALUES(?,?,?,?,?)");
  for (std::size_t i = 0; i < job.case_ids.size(); ++i) {
    c.reset();
    c.bind(1, job.job_id).bind(2, std::int64_t(i / job.cases_per_task)).bind(3, std::int64_t(i));
    c.bind(4, job.case_ids[i]).bind(5, std::int64_t{i < job.resumed.size() && job.resumed[i]});
    c.step();
  }
  t.commit();
}

std::vector<OpenSlurmJob> open_slurm_jobs(Db& db, std::int64_t campaign_id) {
  std::vector<OpenSlurmJob> jobs;
  if (!has_table(db, "slurm_jobs")) return jobs;
  Stmt s(db, "SELECT j.job_id, j.n_tasks, j.n_cases, j.submitted_at, "
             "(SELECT count(*) FROM slurm_tasks t WHERE t.job_id=j.job_id AND t.state='submitted') "
             "FROM slurm_jobs j WHERE j.campaign_id=? AND j.state='submitted' ORDER BY j.submitted_at");
  s.bind(1, campaign_id);
  while (s.step()) jobs.push_back({s.text(0), s.text(3), s.integer(1), s.integer(2), s.integer(4)});
  return jobs;
}

}  // namespace capsim::campaign
