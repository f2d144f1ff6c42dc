// `gbdcs serve` as a child process, as operators run it: a real vision worker on the demo
// timeline (landmark level, cheap), a temp database, port 0, JSON log. The log is drained on
// a thread (kept for assertions) so the server never blocks on a full pipe.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "server_test_support.hpp"

namespace gbdcs::server::testing {

struct ServeProcess {
  // `extra` go after the defaults; CLI11 refuses an option given twice, so `source` replaces
  // the default camera (empty: the demo flight's timeline), and a --worker-silence in `extra`
  // replaces the default 1 s.
  ServeProcess(const std::string& db, const std::vector<std::string>& extra,
               std::string source = {}) {
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe");
    const std::string bin = GBDCS_BINARY;
    if (source.empty())
      source = std::string("timeline:") + GBDCS_SOURCE_DIR + "/fixtures/timelines/demo_flight.json";
    std::vector<std::string> args = {bin,   "serve", "--port", "0",    "--db",         db,
                                     "--source", source, "--web",  "/nonexistent", "--log-json"};
    if (std::find(extra.begin(), extra.end(), "--worker-silence") == extra.end()) {
      args.insert(args.end(), {"--worker-silence", "1"});
    }
    args.insert(args.end(), extra.begin(), extra.end());
    pid = fork();
    if (pid == 0) {
      setpgid(0, 0);  // its own group, as a shell gives a command: interrupt_group()
      dup2(out[1], 1);
      close(out[0]);
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(bin.c_str(), argv.data());
      _exit(127);
    }
    close(out[1]);
    stream = fdopen(out[0], "r");
    char line[8192];
    while (fgets(line, sizeof line, stream)) {
      const std::string s(line);
      keep(s);
      auto at = s.find("listening on http://127.0.0.1:");
      if (at != std::string::npos) {
        port = static_cast<unsigned short>(std::stoi(s.substr(at + 30)));
        break;
      }
    }
    drain = std::thread([this] {
      char buf[65536];
      while (fgets(buf, sizeof buf, stream)) keep(buf);
    });
  }
  ~ServeProcess() { stop(SIGTERM); }

  // Stops the server with `sig` (SIGKILL: no clean-up at all) and, after SIGKILL, its worker
  // too (an orphan would keep trying to reconnect); `whole_group`: to the server's process
  // group. Returns the wait status.
  int stop(int sig, bool whole_group = false) {
    if (stopped) return status;
    stopped = true;
    const auto workers = children();
    kill(whole_group ? -pid : pid, sig);
    waitpid(pid, &status, 0);
    if (sig == SIGKILL) {
      for (auto w : workers) kill(w, SIGKILL);
    }
    if (drain.joinable()) drain.join();
    fclose(stream);
    return status;
  }

  // A Ctrl-C on the terminal: SIGINT to the server's whole process group. Returns the wait
  // status.
  int interrupt_group() { return stop(SIGINT, true); }

  std::vector<pid_t> children() const {
    std::vector<pid_t> out;
    for (const auto& e : std::filesystem::directory_iterator("/proc")) {
      const auto name = e.path().filename().string();
      if (name.find_first_not_of("0123456789") != std::string::npos) continue;
      std::ifstream stat(e.path() / "stat");
      std::string text;
      std::getline(stat, text);
      auto close_paren = text.rfind(')');
      if (close_paren == std::string::npos) continue;
      std::istringstream rest(text.substr(close_paren + 2));
      char state;
      int ppid = 0;
      rest >> state >> ppid;
      if (ppid == pid && state != 'Z') out.push_back(std::stoi(name));
    }
    return out;
  }

  // Log lines so far that contain `needle`.
  std::vector<std::string> log_lines(const std::string& needle) const {
    std::lock_guard lock(log_mutex);
    std::vector<std::string> out;
    for (const auto& l : log) {
      if (l.find(needle) != std::string::npos) out.push_back(l);
    }
    return out;
  }

  pid_t pid = -1;
  FILE* stream = nullptr;
  unsigned short port = 0;
  std::thread drain;
  bool stopped = false;
  int status = 0;
  mutable std::mutex log_mutex;
  std::vector<std::string> log;

 private:
  void keep(const std::string& line) {
    std::lock_guard lock(log_mutex);
    if (log.size() < 20000) log.push_back(line);
  }
};

// Registers (once per database) and logs in; returns the token.
inline std::string register_and_login(unsigned short port, bool fresh = true) {
  const json creds = {{"email", "pilot@example.com"}, {"password", "correct horse battery"}};
  if (fresh) {
    const auto r = http_call(port, "POST", "/api/v1/auth/register", creds.dump());
    if (r.status != 201) throw std::runtime_error("register: " + std::to_string(r.status) + r.body);
  }
  const auto login = http_call(port, "POST", "/api/v1/auth/login", creds.dump());
  if (login.status != 200) throw std::runtime_error("login: " + std::to_string(login.status) + login.body);
  return login.doc()["token"].get<std::string>();
}

}  // namespace gbdcs::server::testing
