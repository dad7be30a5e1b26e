MODULE SelfcalServer
  ! selfcal robot line protocol (docs/robot-protocol.md), ABB side: the SERVER task.
  !
  ! Runs in a task of its own (not the motion task, see README.md) with the option Socket Messaging.
  ! It listens on SC_ADDRESS:SC_PORT, serves one client at a time, answers HELLO, LIMITS, JOINTS, MOVE,
  ! STATUS, STOP and BYE, and hands moves and stops to the motion task (SelfcalMotion.mod) through PERS.
  !
  ! The protocol's rules, as kept here:
  ! - HELLO first: any other request before it (BYE aside) gets `ERR bad_request send HELLO first`.
  ! - One client at a time: a second connection gets `ERR fault busy: ...` and is closed.
  ! - Stop states: an emergency stop or an open run chain (protective stop, a released enabling device)
  !   is latched. STATUS reports it and every MOVE is refused with its code until a person acknowledges:
  !   the input diSC_Ack set while the stop is cleared. Nothing is resumed by this program.
  ! - The arm is stopped (scStopSeq) when the client goes (BYE, EOF, a reset, a line over 64 KiB, a reply
  !   that cannot be sent) and on any error in this task; the motion task also stops the arm by itself
  !   when this task stops (heartbeat).
  !
  ! Limits of RAPID kept in mind: a string holds at most 80 characters, so lines are read byte by byte
  ! from rawbytes into words, and replies are sent in pieces of at most 80 characters with the line end
  ! only after the last piece. num is single precision: numbers are sent with 6 decimals (about 7
  ! significant digits, what a num carries). Angles are degrees in RAPID and radians in the protocol.
  !
  ! Not run on any controller or in RobotStudio: see README.md before the first start, at low speed.

  ! ---- adapt these to the cell (README.md) ----
  CONST string SC_ADDRESS := "192.168.125.1";
  CONST num SC_PORT := 5700;
  CONST string SC_MOTION_TASK := "T_ROB1";
  ! Joint limits (deg) and velocity limits at scaling 1 (deg/s), joint 1 first. Set them within the
  ! controller's own joint bounds and below the arm's rated axis speeds.
  CONST num SC_LOWER_DEG{6} := [-160, -60, -90, -150, -110, -300];
  CONST num SC_UPPER_DEG{6} := [160, 80, 60, 150, 110, 300];
  CONST num SC_VMAX_DEG_S{6} := [30, 30, 30, 30, 30, 30];
  ! ----------------------------------------------

  ! Shared with the motion task (see SelfcalMotion.mod for who writes what).
  PERS num scCmdSeq := 0;
  PERS num scDoneSeq := 0;
  PERS num scStopSeq := 0;
  PERS num scServerBeat := 0;
  PERS num scMotionBeat := 0;
  PERS num scFaultCount := 0;
  PERS string scFaultText := "";
  PERS num scMoveTime := 1;
  PERS jointtarget scTarget := [[0,0,0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];

  CONST num SC_JOINTS := 6;
  CONST num SC_MAX_LINE := 65536;
  CONST num SC_DEG_PER_RAD := 57.2957795;
  CONST string SC_LF := "\0A";

  LOCAL VAR socketdev scListener;
  LOCAL VAR socketdev scClient;
  LOCAL VAR socketdev scExtra;
  LOCAL VAR clock scClock;
  LOCAL VAR bool scConnected := FALSE;
  LOCAL VAR bool scHello := FALSE;
  ! The words of the line being read, and what went wrong with it.
  LOCAL VAR string scTok{12};
  LOCAL VAR num scNTok := 0;
  LOCAL VAR string scCur := "";
  LOCAL VAR bool scTooLong := FALSE;
  LOCAL VAR bool scNotAscii := FALSE;
  LOCAL VAR num scLineBytes := 0;
  ! The reply being assembled (at most 80 characters at a time).
  LOCAL VAR string scOut := "";
  ! The latched stop state: "" or protective_stop, emergency_stop, fault.
  LOCAL VAR string scLatched := "";
  LOCAL VAR string scLatchText := "";
  LOCAL VAR num scFaultSeen := 0;
  LOCAL VAR num scSeenMotionBeat := 0;
  LOCAL VAR num scMotionBeatTime := 0;

  PROC main()
    ClkReset scClock;
    ClkStart scClock;
    scFaultSeen := scFaultCount;
    sc_open_listener;
    WHILE TRUE DO
      sc_wait_for_client;
      sc_serve_client;
    ENDWHILE
  ERROR
    ! Anything unexpected in this task: stop the arm, drop every socket, start the cycle again.
    sc_stop_arm;
    sc_close scClient;
    sc_close scExtra;
    sc_close scListener;
    WaitTime 1;
    ExitCycle;
  ENDPROC

  LOCAL PROC sc_close(VAR socketdev s)
    IF SocketGetStatus(s) <> SOCKET_CLOSED THEN
      SocketClose s;
    ENDIF
  ENDPROC

  LOCAL PROC sc_open_listener()
    sc_close scListener;
    SocketCreate scListener;
    SocketBind scListener, SC_ADDRESS, SC_PORT;
    SocketListen scListener;
  ENDPROC

  ! A client waiting in the listen queue, accepted into s; FALSE when none came within the time-out.
  LOCAL FUNC bool sc_try_accept(VAR socketdev s)
    sc_close s;
    SocketAccept scListener, s \Time:=0.05;
    RETURN TRUE;
  ERROR
    IF ERRNO = ERR_SOCK_TIMEOUT THEN
      SkipWarn;
      RETURN FALSE;
    ENDIF
    RAISE;
  ENDFUNC

  LOCAL PROC sc_wait_for_client()
    VAR bool accepted := FALSE;
    WHILE NOT accepted DO
      sc_poll_controller;
      accepted := sc_try_accept(scClient);
    ENDWHILE
    scConnected := TRUE;
    scHello := FALSE;
    sc_reset_line;
  ENDPROC

  LOCAL PROC sc_serve_client()
    VAR rawbytes buf;
    VAR num n;
    WHILE scConnected DO
      sc_poll_controller;
      sc_refuse_second_client;
      n := sc_receive(buf);
      IF n < 0 THEN
        sc_drop_client "connection closed by the client";
      ELSEIF n > 0 THEN
        sc_take_bytes buf, n;
      ENDIF
    ENDWHILE
  ERROR
    ! A failure while serving (a reply that cannot be sent, the controller's calls): stop the arm and drop
    ! the client, as the protocol asks when the server loses the arm.
    SkipWarn;
    sc_drop_client "error " + NumToStr(ERRNO, 0) + " while serving";
    RETURN;
  ENDPROC

  ! Bytes received (up to 1024), 0 when nothing came within the time-out, -1 when the client closed.
  LOCAL FUNC num sc_receive(VAR rawbytes buf)
    VAR num n := 0;
    ClearRawBytes buf;
    SocketReceive scClient \RawData:=buf \NoRecBytes:=n \Time:=0.05;
    RETURN n;
  ERROR
    IF ERRNO = ERR_SOCK_TIMEOUT THEN
      SkipWarn;
      RETURN 0;
    ELSEIF ERRNO = ERR_SOCK_CLOSED THEN
      SkipWarn;
      RETURN -1;
    ENDIF
    RAISE;
  ENDFUNC

  ! One client at a time: a second connection is told so and closed; the first one goes on.
  LOCAL PROC sc_refuse_second_client()
    IF sc_try_accept(scExtra) THEN
      SocketSend scExtra \Str:="ERR fault busy: another client is connected" + SC_LF;
      sc_close scExtra;
    ENDIF
  ERROR
    SkipWarn;
    sc_close scExtra;
    RETURN;
  ENDPROC

  LOCAL PROC sc_drop_client(string why)
    sc_stop_arm;
    sc_close scClient;
    scConnected := FALSE;
    scHello := FALSE;
    ErrWrite \I, "selfcal server", "client gone: " + why;
  ENDPROC

  ! Ask the motion task to stop now; valid in every state, any number of times.
  LOCAL PROC sc_stop_arm()
    scStopSeq := scStopSeq + 1;
  ENDPROC

  ! Heartbeat, the motion task's heartbeat, and the latched stop states.
  LOCAL PROC sc_poll_controller()
    scServerBeat := scServerBeat + 1;
    IF scMotionBeat <> scSeenMotionBeat THEN
      scSeenMotionBeat := scMotionBeat;
      scMotionBeatTime := ClkRead(scClock);
    ENDIF
    IF DOutput(doSC_EStop) = 1 THEN
      sc_latch "emergency_stop", "emergency stop at the controller";
    ELSEIF DOutput(doSC_RunChainOk) = 0 THEN
      sc_latch "protective_stop", "run chain open (protective stop or enabling device)";
    ENDIF
    IF scFaultCount <> scFaultSeen THEN
      scFaultSeen := scFaultCount;
      sc_latch "fault", scFaultText;
    ENDIF
    IF scLatched <> "" AND DInput(diSC_Ack) = 1 AND DOutput(doSC_EStop) = 0 AND DOutput(doSC_RunChainOk) = 1 THEN
      ErrWrite \I, "selfcal server", scLatched + " acknowledged by a person";
      scLatched := "";
      scLatchText := "";
    ENDIF
  ENDPROC

  LOCAL PROC sc_latch(string state, string text)
    IF scLatched = "" OR (state = "emergency_stop" AND scLatched <> state) THEN
      scLatched := state;
      scLatchText := text;
      sc_stop_arm;
    ENDIF
  ENDPROC

  ! ---- reading lines ----

  LOCAL PROC sc_reset_line()
    scNTok := 0;
    scCur := "";
    scTooLong := FALSE;
    scNotAscii := FALSE;
    scLineBytes := 0;
  ENDPROC

  LOCAL PROC sc_take_bytes(VAR rawbytes buf, num n)
    VAR byte b;
    FOR i FROM 1 TO n DO
      UnpackRawBytes buf, i, b \Hex1;
      scLineBytes := scLineBytes + 1;
      IF b = 10 THEN
        sc_end_word;
        sc_handle_line;
        sc_reset_line;
        IF NOT scConnected THEN
          RETURN;
        ENDIF
      ELSEIF b = 13 OR b = 32 OR b = 9 THEN
        ! A CR before the LF is tolerated, and runs of spaces are accepted.
        sc_end_word;
      ELSEIF b < 33 OR b > 126 THEN
        scNotAscii := TRUE;
      ELSEIF StrLen(scCur) >= 60 THEN
        scTooLong := TRUE;
      ELSE
        scCur := scCur + ByteToStr(b \Char);
      ENDIF
      IF scLineBytes >= SC_MAX_LINE THEN
        sc_reply "ERR bad_request line too long";
        sc_drop_client "a line over 65536 bytes";
        RETURN;
      ENDIF
    ENDFOR
  ENDPROC

  LOCAL PROC sc_end_word()
    IF scCur <> "" THEN
      IF scNTok >= 12 THEN
        scTooLong := TRUE;
      ELSE
        scNTok := scNTok + 1;
        scTok{scNTok} := scCur;
      ENDIF
      scCur := "";
    ENDIF
  ENDPROC

  ! ---- writing replies: pieces of at most 80 characters, the line end after the last ----

  LOCAL PROC sc_put(string piece)
    IF StrLen(scOut) + StrLen(piece) > 80 THEN
      SocketSend scClient \Str:=scOut;
      scOut := "";
    ENDIF
    scOut := scOut + piece;
  ENDPROC

  LOCAL PROC sc_end_reply()
    IF StrLen(scOut) >= 80 THEN
      SocketSend scClient \Str:=scOut;
      scOut := "";
    ENDIF
    SocketSend scClient \Str:=scOut + SC_LF;
    scOut := "";
  ENDPROC

  LOCAL PROC sc_reply(string line)
    scOut := "";
    sc_put line;
    sc_end_reply;
  ENDPROC

  ! An identity value, percent-encoded: %, = and every byte outside ! .. ~ become %XX.
  LOCAL PROC sc_put_encoded(string value)
    VAR string ch;
    VAR byte code;
    FOR i FROM 1 TO StrLen(value) DO
      ch := StrPart(value, i, 1);
      code := StrToByte(ch \Char);
      IF code >= 33 AND code <= 126 AND code <> 37 AND code <> 61 THEN
        sc_put ch;
      ELSE
        sc_put "%" + ByteToStr(code \Hex);
      ENDIF
    ENDFOR
  ENDPROC

  LOCAL FUNC string sc_num(num value)
    RETURN NumToStr(value, 6);
  ENDFUNC

  LOCAL FUNC num sc_axis(robjoint r, num j)
    TEST j
    CASE 1:
      RETURN r.rax_1;
    CASE 2:
      RETURN r.rax_2;
    CASE 3:
      RETURN r.rax_3;
    CASE 4:
      RETURN r.rax_4;
    CASE 5:
      RETURN r.rax_5;
    DEFAULT:
      RETURN r.rax_6;
    ENDTEST
  ENDFUNC

  ! ---- requests ----

  LOCAL PROC sc_handle_line()
    VAR string word;
    IF scNotAscii THEN
      sc_reply "ERR bad_request not ASCII";
      RETURN;
    ENDIF
    IF scTooLong THEN
      sc_reply "ERR bad_request a word or the number of words is too long";
      RETURN;
    ENDIF
    IF scNTok = 0 THEN
      sc_reply "ERR bad_request empty request";
      RETURN;
    ENDIF
    word := scTok{1};
    IF word = "BYE" THEN
      sc_reply "OK";
      sc_drop_client "BYE";
    ELSEIF word = "HELLO" THEN
      sc_hello;
    ELSEIF NOT scHello THEN
      sc_reply "ERR bad_request send HELLO first";
    ELSEIF word = "MOVE" THEN
      sc_move;
    ELSEIF word <> "LIMITS" AND word <> "JOINTS" AND word <> "STATUS" AND word <> "STOP" THEN
      sc_reply "ERR bad_request unknown request " + StrPart(word, 1, sc_min(StrLen(word), 40));
    ELSEIF scNTok > 1 THEN
      sc_reply "ERR bad_request " + word + " takes no arguments";
    ELSEIF word = "LIMITS" THEN
      sc_limits;
    ELSEIF word = "JOINTS" THEN
      sc_joints;
    ELSEIF word = "STATUS" THEN
      sc_status;
    ELSE
      ! STOP
      sc_stop_arm;
      sc_reply "OK";
    ENDIF
  ENDPROC

  LOCAL FUNC num sc_min(num a, num b)
    IF a < b THEN
      RETURN a;
    ENDIF
    RETURN b;
  ENDFUNC

  LOCAL PROC sc_hello()
    IF scNTok <> 3 OR scTok{2} <> "selfcal-robot" OR scTok{3} <> "1" THEN
      sc_reply "ERR bad_request unsupported protocol (this server speaks selfcal-robot 1)";
      RETURN;
    ENDIF
    scHello := TRUE;
    scOut := "";
    sc_put "OK selfcal-robot 1 model=";
    sc_put_encoded GetSysInfo(\RobotType);
    sc_put " serial=";
    sc_put_encoded GetSysInfo(\SerialNo);
    sc_put " calibration=";
    sc_put_encoded GetSysInfo(\SWVersion);
    sc_put " joints=" + NumToStr(SC_JOINTS, 0) + " real=1";
    sc_end_reply;
  ENDPROC

  LOCAL PROC sc_limits()
    scOut := "";
    sc_put "OK";
    FOR j FROM 1 TO SC_JOINTS DO
      sc_put " " + sc_num(SC_LOWER_DEG{j} / SC_DEG_PER_RAD);
    ENDFOR
    FOR j FROM 1 TO SC_JOINTS DO
      sc_put " " + sc_num(SC_UPPER_DEG{j} / SC_DEG_PER_RAD);
    ENDFOR
    FOR j FROM 1 TO SC_JOINTS DO
      sc_put " " + sc_num(SC_VMAX_DEG_S{j} / SC_DEG_PER_RAD);
    ENDFOR
    sc_end_reply;
  ENDPROC

  LOCAL PROC sc_joints()
    VAR jointtarget now;
    now := CJointT(\TaskName:=SC_MOTION_TASK);
    scOut := "";
    sc_put "OK " + NumToStr(ClkRead(scClock), 3);
    FOR j FROM 1 TO SC_JOINTS DO
      sc_put " " + sc_num(sc_axis(now.robax, j) / SC_DEG_PER_RAD);
    ENDFOR
    ! RAPID gives no joint velocities here: the protocol allows zeros.
    FOR j FROM 1 TO SC_JOINTS DO
      sc_put " 0";
    ENDFOR
    sc_end_reply;
  ENDPROC

  LOCAL PROC sc_status()
    scOut := "";
    IF scLatched <> "" THEN
      sc_put "OK " + scLatched + " ";
      sc_put scLatchText;
      sc_put "; acknowledge it at the controller";
    ELSEIF scCmdSeq <> scDoneSeq THEN
      sc_put "OK moving move #" + NumToStr(scCmdSeq, 0);
    ELSE
      sc_put "OK idle";
    ENDIF
    sc_end_reply;
  ENDPROC

  ! A number of the protocol into value; "" when it parsed, else the refusal to send.
  LOCAL FUNC string sc_parse(string word, INOUT num value)
    VAR string text;
    text := word;
    IF text = "nan" OR text = "inf" OR text = "-inf" OR text = "+inf" THEN
      RETURN "ERR rejected a value is not finite";
    ENDIF
    IF StrPart(text, 1, 1) = "+" AND StrLen(text) > 1 THEN
      text := StrPart(text, 2, StrLen(text) - 1);
    ENDIF
    IF NOT StrToVal(text, value) THEN
      RETURN "ERR bad_request MOVE needs numbers";
    ENDIF
    RETURN "";
  ENDFUNC

  LOCAL PROC sc_move()
    VAR num scaling;
    VAR num q{6};
    VAR num value;
    VAR string refusal;
    VAR jointtarget now;
    VAR num duration;
    VAR num t;

    IF scNTok <> SC_JOINTS + 2 THEN
      sc_reply "ERR bad_request MOVE needs a scaling and 6 joints, got " + NumToStr(scNTok - 1, 0) + " numbers";
      RETURN;
    ENDIF
    refusal := sc_parse(scTok{2}, scaling);
    FOR j FROM 1 TO SC_JOINTS DO
      IF refusal = "" THEN
        refusal := sc_parse(scTok{j + 2}, value);
        q{j} := value * SC_DEG_PER_RAD;
      ENDIF
    ENDFOR
    IF refusal <> "" THEN
      sc_reply refusal;
      RETURN;
    ENDIF
    IF scaling <= 0 OR scaling > 1 THEN
      sc_reply "ERR rejected scaling " + sc_num(scaling) + " not in (0, 1]";
      RETURN;
    ENDIF
    FOR j FROM 1 TO SC_JOINTS DO
      IF q{j} < SC_LOWER_DEG{j} OR q{j} > SC_UPPER_DEG{j} THEN
        sc_reply "ERR rejected joint " + NumToStr(j, 0) + " outside its limits";
        RETURN;
      ENDIF
    ENDFOR
    IF scLatched <> "" THEN
      scOut := "";
      sc_put "ERR " + scLatched + " move refused: ";
      sc_put scLatchText;
      sc_end_reply;
      RETURN;
    ENDIF
    IF scCmdSeq <> scDoneSeq THEN
      sc_reply "ERR rejected the arm is still moving";
      RETURN;
    ENDIF
    IF ClkRead(scClock) - scMotionBeatTime > 0.5 THEN
      sc_reply "ERR rejected the motion task " + SC_MOTION_TASK + " is not running";
      RETURN;
    ENDIF
    ! The duration at scaling of the velocity limits, with the margin of a smooth profile whose peak
    ! speed is 1.875 times its mean (the controller's own ramps stay below it).
    now := CJointT(\TaskName:=SC_MOTION_TASK);
    duration := 0.1;
    FOR j FROM 1 TO SC_JOINTS DO
      t := 1.875 * Abs(q{j} - sc_axis(now.robax, j)) / (SC_VMAX_DEG_S{j} * scaling);
      IF t > duration THEN
        duration := t;
      ENDIF
    ENDFOR
    scTarget := now;
    scTarget.robax.rax_1 := q{1};
    scTarget.robax.rax_2 := q{2};
    scTarget.robax.rax_3 := q{3};
    scTarget.robax.rax_4 := q{4};
    scTarget.robax.rax_5 := q{5};
    scTarget.robax.rax_6 := q{6};
    scMoveTime := duration;
    ! Last: the motion task starts when the sequence number changes.
    scCmdSeq := scCmdSeq + 1;
    sc_reply "OK";
  ENDPROC
ENDMODULE
