// The manual robot: a `Robot` for arms without a programming interface. A person is the controller: the
// backend prints each target in degrees and waits for the operator to jog the arm there with the teach
// pendant and type `done`; joint readings come from a `joint_reader` (any Robot that can read the
// encoders, e.g. a network robot whose server cannot move the arm) or are typed in by the operator.
//
// It never assumes a target was reached: a reading after `done` is a real reading (the reader's, or the
// values the operator reads off the pendant), and the session compares it with the target as with any
// backend (R4, R8). Identity: backend "manual", real_hardware true (a person moves a real arm: R1, R12).
//
// Blocking: GetStatus and ReadJoints (without a reader) read one line from `in` per call and so wait for
// the operator; a session's motion watchdog (R6) must allow for a person's pace with this backend.
// Not thread-safe.
#pragma once

#include <iosfwd>
#include <string>

#include "base/status.h"
#include "robot/clock.h"
#include "robot/robot.h"

namespace selfcal::robot {

class ManualRobot : public Robot {
 public:
  // `in`, `out`, `clock` and `joint_reader` must outlive the robot. Throws InvalidArgument on invalid
  // limits (CheckJointLimits; velocity limits are only used for the scaling check).
  ManualRobot(std::istream& in, std::ostream& out, JointLimits limits, Clock& clock, Robot* joint_reader = nullptr);

  // Connects the reader (if any) and explains the procedure to the operator.
  Status Connect() override;
  void Disconnect() override;
  // backend "manual", real_hardware true; model, serial and calibration id from the reader when there
  // is one, else model "manual".
  Result<RobotIdentity> Identity() override;
  Result<JointLimits> Limits() override;
  // From the reader; else asks the operator for the joints in degrees (count, finiteness and limits
  // checked; asked again up to kMaxReAsks times, then kBadReading; `abort` or end of input ->
  // kOperatorAbort). Stamped with clock.Now() when the answer arrived; velocities are zeros.
  Result<JointReading> ReadJoints() override;
  // Refuses (kRejected) a bad target (CheckMoveTarget) or a move while the operator still jogs the last
  // one; otherwise prints the target in degrees and the per-joint difference from the last reading.
  Status StartMove(const Eigen::VectorXd& target_rad, double velocity_scaling) override;
  // kIdle when no move waits for the operator. Otherwise reads one answer: `done` -> kIdle; `abort` or end
  // of input -> kOperatorAbort; anything else (an empty line) -> kMoving after a reminder.
  Result<RobotStatus> GetStatus() override;
  // Tells the operator to stop and cancels the move waiting for `done`; stops the reader too.
  Status Stop() override;

  static constexpr int kMaxReAsks = 3;

 private:
  Status CheckConnected(const char* call) const;
  // One line from `in`; false at end of input.
  bool ReadAnswer(std::string* answer);
  // The joints typed on `answer` in rad, or why they are not acceptable.
  std::string ParseTypedJoints(const std::string& answer, Eigen::VectorXd* joints_rad) const;

  std::istream& in_;
  std::ostream& out_;
  JointLimits limits_;
  Clock& clock_;
  Robot* joint_reader_;
  bool connected_ = false;
  bool awaiting_operator_ = false;
  int moves_ = 0;
  Eigen::VectorXd last_joints_rad_;  // last reading; empty before the first
};

}  // namespace selfcal::robot
