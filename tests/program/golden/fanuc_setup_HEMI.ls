/PROG  HEMI
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "waam-slicer";
PROG_SIZE	= 0;
CREATE		= DATE 00-01-01  TIME 00:00:00;
MODIFIED	= DATE 00-01-01  TIME 00:00:00;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 50;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000001 00000000;
/APPL
  ARC : TRUE ;
  ARC Welding Equipment : 1,*,*,*,*;
/MN
   1:  ! FRAMES: X,Y,Z MM W,P,R DEG ;
   2:  ! UFRAME[1] = REMOTE TCP AT TORCH ;
   3:  ! UF1 X,Y=1045.747,-630.155 ;
   4:  ! UF1 Z,W=653.167,180.000 ;
   5:  ! UF1 P,R=0.000,0.000 ;
   6:  ! UTOOL[1] = FLANGE ;
   7:  ! UT1 X,Y=0.000,0.000 ;
   8:  ! UT1 Z,W=0.000,0.000 ;
   9:  ! UT1 P,R=0.000,0.000 ;
  10:  UFRAME_NUM=1 ;
  11:  UTOOL_NUM=1 ;
  12:  ! WELD SCHED 1: WFS 10.00 MM/S ;
  13:J P[21] 10% FINE    ;
  14:  $PLST_GRP1[1].$PAYLOAD=2.500 ;
  15:  $PLST_GRP1[1].$PAYLOAD_X=0.000 ;
  16:  $PLST_GRP1[1].$PAYLOAD_Y=0.000 ;
  17:  $PLST_GRP1[1].$PAYLOAD_Z=4.000 ;
  18:  PAYLOAD[1] ;
  19:J P[1] 10% FINE    ;
  20:L P[2] 120cm/min FINE RTCP    ;
  21:  Weld Start[2,1] ;
  22:L P[3] 36cm/min CNT100 RTCP    ;
  23:L P[4] 36cm/min CNT100 RTCP    ;
  24:L P[5] 36cm/min CNT100 RTCP    ;
  25:L P[6] 36cm/min CNT100 RTCP    ;
  26:L P[7] 36cm/min CNT100 RTCP    ;
  27:L P[8] 36cm/min CNT100 RTCP    ;
  28:L P[9] 36cm/min FINE RTCP    ;
  29:  Weld End[2,1] ;
  30:L P[10] 120cm/min FINE RTCP    ;
  31:  $PLST_GRP1[1].$PAYLOAD=2.600 ;
  32:  $PLST_GRP1[1].$PAYLOAD_X=0.000 ;
  33:  $PLST_GRP1[1].$PAYLOAD_Y=0.000 ;
  34:  $PLST_GRP1[1].$PAYLOAD_Z=4.150 ;
  35:  PAYLOAD[1] ;
  36:  WAIT  30.00(sec) ;
  37:  WAIT DI[3]=ON    ;
  38:J P[11] 10% FINE    ;
  39:L P[12] 120cm/min FINE RTCP    ;
  40:  Weld Start[2,1] ;
  41:L P[13] 36cm/min CNT100 RTCP    ;
  42:L P[14] 36cm/min CNT100 RTCP    ;
  43:L P[15] 36cm/min CNT100 RTCP    ;
  44:L P[16] 36cm/min CNT100 RTCP    ;
  45:L P[17] 36cm/min CNT100 RTCP    ;
  46:L P[18] 36cm/min CNT100 RTCP    ;
  47:L P[19] 36cm/min FINE RTCP    ;
  48:  Weld End[2,1] ;
  49:L P[20] 120cm/min FINE RTCP    ;
  50:J P[21] 10% FINE    ;
/POS
P[1]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    14.1189 deg,	J3=   -32.1703 deg,
	J4=     0.0000 deg,	J5=   122.1703 deg,	J6=   147.8020 deg
};
P[2]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    13.7468 deg,	J3=   -30.8941 deg,
	J4=     0.0000 deg,	J5=   120.8941 deg,	J6=   147.8020 deg
};
P[3]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    13.7468 deg,	J3=   -30.8941 deg,
	J4=     0.0000 deg,	J5=   120.8941 deg,	J6=   192.8020 deg
};
P[4]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    13.7468 deg,	J3=   -30.8941 deg,
	J4=     0.0000 deg,	J5=   120.8941 deg,	J6=   237.8020 deg
};
P[5]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    13.7468 deg,	J3=   -30.8941 deg,
	J4=     0.0000 deg,	J5=   120.8941 deg,	J6=   282.8020 deg
};
P[6]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    13.7468 deg,	J3=   -30.8941 deg,
	J4=     0.0000 deg,	J5=   120.8941 deg,	J6=   327.8020 deg
};
P[7]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    13.7468 deg,	J3=   -30.8941 deg,
	J4=     0.0000 deg,	J5=   120.8941 deg,	J6=   372.8020 deg
};
P[8]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    13.7468 deg,	J3=   -30.8941 deg,
	J4=     0.0000 deg,	J5=   120.8941 deg,	J6=   417.8020 deg
};
P[9]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    13.7468 deg,	J3=   -30.8941 deg,
	J4=     0.0000 deg,	J5=   120.8941 deg,	J6=   462.8020 deg
};
P[10]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.1980 deg,	J2=    14.1189 deg,	J3=   -32.1703 deg,
	J4=     0.0000 deg,	J5=   122.1703 deg,	J6=   462.8020 deg
};
P[11]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.4520 deg,	J3=   -32.2777 deg,
	J4=     3.8274 deg,	J5=   116.8498 deg,	J6=   149.4045 deg
};
P[12]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.0772 deg,	J3=   -30.9975 deg,
	J4=     3.7856 deg,	J5=   115.5724 deg,	J6=   149.3098 deg
};
P[13]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.0772 deg,	J3=   -30.9975 deg,
	J4=     3.7856 deg,	J5=   115.5724 deg,	J6=   194.3098 deg
};
P[14]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.0772 deg,	J3=   -30.9975 deg,
	J4=     3.7856 deg,	J5=   115.5724 deg,	J6=   239.3098 deg
};
P[15]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.0772 deg,	J3=   -30.9975 deg,
	J4=     3.7856 deg,	J5=   115.5724 deg,	J6=   284.3098 deg
};
P[16]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.0772 deg,	J3=   -30.9975 deg,
	J4=     3.7856 deg,	J5=   115.5724 deg,	J6=   329.3098 deg
};
P[17]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.0772 deg,	J3=   -30.9975 deg,
	J4=     3.7856 deg,	J5=   115.5724 deg,	J6=   374.3098 deg
};
P[18]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.0772 deg,	J3=   -30.9975 deg,
	J4=     3.7856 deg,	J5=   115.5724 deg,	J6=   419.3098 deg
};
P[19]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.0772 deg,	J3=   -30.9975 deg,
	J4=     3.7856 deg,	J5=   115.5724 deg,	J6=   464.3098 deg
};
P[20]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.4520 deg,	J3=   -32.2777 deg,
	J4=     3.8274 deg,	J5=   116.8498 deg,	J6=   464.4045 deg
};
P[21]{
   GP1:
	UF : 1, UT : 1,	
	J1=   -32.4865 deg,	J2=    13.4520 deg,	J3=   -32.2777 deg,
	J4=     3.8274 deg,	J5=   116.8498 deg,	J6=   464.4045 deg
};
/END
