// A driver wrapper for tests that must see what the server asked of a real
// driver: it forwards every call to the wrapped driver and first tells an
// observer about Execute, Track, Halt and Resume. The observer runs on the
// RobotDaemon's thread; it must lock whatever the test thread reads.
#pragma once

#include "robotalk/driver.h"

#include <memory>
#include <utility>
#include <vector>

namespace robotalk::testing {

class DriverObserver {
 public:
  virtual ~DriverObserver() = default;
  virtual void Executed(const DriverCommand& /*command*/, TimePoint /*now*/) {}
  virtual void Tracked(const JointReference& /*reference*/, TimePoint /*now*/) {}
  virtual void Halted(bool /*halted*/) {}
};

class ObservedDriver final : public Driver {
 public:
  ObservedDriver(std::unique_ptr<Driver> inner, std::shared_ptr<DriverObserver> observer)
      : inner_(std::move(inner)), observer_(std::move(observer)) {}
  const RobotModel& model() const override { return inner_->model(); }
  Duration period() const override { return inner_->period(); }
  DriverResult Execute(const DriverCommand& c, TimePoint now, std::vector<Completion>& done) override {
    observer_->Executed(c, now);
    return inner_->Execute(c, now, done);
  }
  DriverResult Track(const JointReference& r, TimePoint now, std::vector<Completion>& done) override {
    observer_->Tracked(r, now);
    return inner_->Track(r, now, done);
  }
  DriverResult TrackBase(const BaseReference& r, TimePoint now, std::vector<Completion>& done) override {
    return inner_->TrackBase(r, now, done);
  }
  void Update(TimePoint now, std::vector<Completion>& done) override { inner_->Update(now, done); }
  void ReadState(RobotState& s) const override { inner_->ReadState(s); }
  void Stop(TimePoint now, std::vector<Completion>& done) override { inner_->Stop(now, done); }
  void StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& done) override {
    inner_->StopOnly(scope, now, done);
  }
  void Halt(std::vector<Completion>& done) override {
    observer_->Halted(true);
    inner_->Halt(done);
  }
  void Resume() override {
    observer_->Halted(false);
    inner_->Resume();
  }
  std::string_view Fault() const override { return inner_->Fault(); }

 private:
  std::unique_ptr<Driver> inner_;
  std::shared_ptr<DriverObserver> observer_;
};

}  // namespace robotalk::testing
