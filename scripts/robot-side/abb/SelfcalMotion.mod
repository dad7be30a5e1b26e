MODULE SelfcalMotion
  ! selfcal robot line protocol (docs/robot-protocol.md), ABB side: the MOTION task.
  !
  ! Load this module into the robot's motion task (T_ROB1). The server task (SelfcalServer.mod) accepts the
  ! client's MOVE and STOP requests and hands them over through the PERS data below; this task only moves.
  !
  ! - A MOVE becomes one MoveAbsJ to scTarget with the time scMoveTime (\T), computed by the server from
  !   the velocity limits and the client's scaling, ending in a fine point.
  ! - Every stop request (STOP, the client gone, an error in the server) increments scStopSeq. An
  !   interrupt on that PERS (IPers) stops the arm at once (StopMove \Quick), throws the rest of the path
  !   away (ClearPath) and starts the cycle again without the move: nothing is ever resumed.
  ! - A timer interrupt watches the server's heartbeat: if the server task stops while a move is running,
  !   the arm is stopped the same way (the arm never moves without a server, and so a client, watching).
  ! - When main starts (power on, PP to Main, after an ExitCycle), a move that was accepted but not run is
  !   dropped, never run later.
  !
  ! Not run on any controller or in RobotStudio: see README.md before the first start, at low speed.

  ! Shared with the server task (same names, types and initial values in both modules). One task writes
  ! each of them: the server writes scCmdSeq, scTarget, scMoveTime, scStopSeq and scServerBeat; this task
  ! writes scDoneSeq, scMotionBeat, scFaultCount and scFaultText.
  PERS num scCmdSeq := 0;
  PERS num scDoneSeq := 0;
  PERS num scStopSeq := 0;
  PERS num scServerBeat := 0;
  PERS num scMotionBeat := 0;
  PERS num scFaultCount := 0;
  PERS string scFaultText := "";
  PERS num scMoveTime := 1;
  PERS jointtarget scTarget := [[0,0,0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];

  ! The tool used for MoveAbsJ. The joint target does not depend on it; keep tool0 unless your cell's
  ! motion supervision needs the real load: then put your tooldata here.
  PERS tooldata scTool := [TRUE,[[0,0,0],[1,0,0,0]],[0.001,[0,0,0.001],[1,0,0,0],0,0,0]];

  ! Seconds without a new server heartbeat after which a running move is stopped.
  CONST num SC_SERVER_SILENCE := 1.0;

  LOCAL VAR intnum scStopIntr;
  LOCAL VAR intnum scWatchIntr;
  LOCAL VAR num scSeenServerBeat := 0;
  LOCAL VAR num scSilentTicks := 0;

  PROC main()
    ! Interrupts are connected again on every start of the cycle (ExitCycle keeps old connections).
    IDelete scStopIntr;
    CONNECT scStopIntr WITH sc_stop_trap;
    IPers scStopSeq, scStopIntr;
    IDelete scWatchIntr;
    CONNECT scWatchIntr WITH sc_watch_trap;
    ITimer 0.2, scWatchIntr;
    ! Whatever was accepted before this start is dropped: a move is never run late.
    scDoneSeq := scCmdSeq;
    scSeenServerBeat := scServerBeat;
    scSilentTicks := 0;
    WHILE TRUE DO
      IF scCmdSeq <> scDoneSeq THEN
        sc_run_move;
      ELSE
        scMotionBeat := scMotionBeat + 1;
        WaitTime 0.05;
      ENDIF
    ENDWHILE
  ENDPROC

  LOCAL PROC sc_run_move()
    VAR num seq;
    VAR jointtarget target;
    VAR num duration;

    seq := scCmdSeq;
    target := scTarget;
    duration := scMoveTime;
    scMotionBeat := scMotionBeat + 1;
    ! The time argument sets the duration; the speeddata is required by the syntax but \T governs.
    MoveAbsJ target, v100 \T:=duration, fine, scTool;
    scDoneSeq := seq;
  ERROR
    ! The controller refused or broke off the move (out of reach, a joint limit, motion supervision, ...):
    ! tell the server, which reports `fault` until a person acknowledges, and run nothing more of it.
    scFaultText := "motion task: MoveAbsJ failed, error " + NumToStr(ERRNO, 0);
    scFaultCount := scFaultCount + 1;
    StopMove \Quick;
    ClearPath;
    StartMove;
    scDoneSeq := seq;
    RETURN;
  ENDPROC

  LOCAL PROC sc_abandon_path()
    StopMove \Quick;
    ClearPath;
    StartMove;
    scDoneSeq := scCmdSeq;
    ! Back to the top of main: the interrupted MoveAbsJ is gone, not paused.
    ExitCycle;
  ENDPROC

  LOCAL TRAP sc_stop_trap
    sc_abandon_path;
  ENDTRAP

  LOCAL TRAP sc_watch_trap
    IF scServerBeat <> scSeenServerBeat THEN
      scSeenServerBeat := scServerBeat;
      scSilentTicks := 0;
    ELSE
      scSilentTicks := scSilentTicks + 1;
    ENDIF
    IF scCmdSeq <> scDoneSeq AND scSilentTicks * 0.2 >= SC_SERVER_SILENCE THEN
      scFaultText := "motion task: the server task stopped during a move";
      scFaultCount := scFaultCount + 1;
      sc_abandon_path;
    ENDIF
  ENDTRAP
ENDMODULE
