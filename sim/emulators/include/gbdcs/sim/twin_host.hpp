// TwinHost: one TwinSim stepped on a Clock, shared by the protocol emulators (Tello, AirSim,
// XFly) that let real adapters and third-party clients fly the twin over sockets.
//
// Time   : simulated time = clock.now() - clock.now() at construction.
//          lockstep (default): poll() advances the twin to the clock's now in step_s chunks
//            (tests and the scenario runner on a ManualClock).
//          realtime: start() runs a thread that does the same realtime_step_hz times a second
//            (give it a SteadyClock: `gbdcs twin --tello`); stop() or the destructor joins it.
// Hooks  : add_listener(fn) -> fn(sim, t_s) after every chunk, with the host's lock held: the
//          emulators send their state streams and deferred replies from there.
// Threads: every access to the TwinSim goes through with_sim() (the host's lock), so the
//          emulators' I/O threads, the stepping thread and a renderer never race. Lock order:
//          the host's lock, then an emulator's own.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "gbdcs/contracts/clock.hpp"
#include "gbdcs/sim/twin_sim.hpp"

namespace gbdcs::sim {

struct TwinHostOptions {
  std::uint32_t seed = 1;
  TwinOptions twin;
  double step_s = 0.01;           // listeners run at least this often (simulated seconds)
  double realtime_step_hz = 200;  // realtime: how often the thread advances
};

class TwinHost {
 public:
  using Listener = std::function<void(TwinSim&, double t_s)>;

  TwinHost(const contracts::Clock& clock, std::shared_ptr<const TwinModel> model,
           TwinHostOptions options = {});
  ~TwinHost();
  TwinHost(const TwinHost&) = delete;
  TwinHost& operator=(const TwinHost&) = delete;

  void poll();  // lockstep: advance to the clock's now
  void start();  // realtime thread
  void stop();
  double sim_time_s() const;
  const contracts::Clock& clock() const { return clock_; }

  template <class Fn>
  auto with_sim(Fn&& fn) {
    std::lock_guard lock(mutex_);
    return fn(*sim_);
  }
  int add_listener(Listener listener);
  void remove_listener(int id);

 private:
  void advance_locked(double t_s);
  double clock_sim_s() const;

  const contracts::Clock& clock_;
  TwinHostOptions options_;
  contracts::Duration origin_;
  std::recursive_mutex mutex_;  // a listener may call with_sim() again
  std::unique_ptr<TwinSim> sim_;
  double advanced_to_s_ = 0;
  std::map<int, Listener> listeners_;
  int next_listener_ = 1;

  std::mutex thread_mutex_;
  std::condition_variable thread_cv_;
  bool thread_stop_ = false;
  std::thread thread_;
};

}  // namespace gbdcs::sim
